#include "engine/io/map_svg.h"

#include <gtest/gtest.h>

#include <string>

#include "engine/io/movingai_map.h"
#include "engine/map/map_builder.h"

namespace dispatch::engine {
namespace {

std::size_t Count(const std::string& text, const std::string& needle) {
  std::size_t n = 0;
  for (std::size_t pos = text.find(needle); pos != std::string::npos;
       pos = text.find(needle, pos + needle.size())) {
    ++n;
  }
  return n;
}

// The cy attribute of the circle drawn for a point (detailed style).
double CircleY(const std::string& svg, const std::string& point) {
  const std::size_t title = svg.find("<title>" + point + "</title></circle>");
  EXPECT_NE(title, std::string::npos) << point;
  const std::size_t cy = svg.rfind("cy=\"", title);
  return std::stod(svg.substr(cy + 4));
}

// Two shelves, three one-way paths, two single lanes, an intersection and a station.
MapBuilder SampleBuilder() {
  MapBuilder b("svg <sample>");
  b.SetFloor({0, 0}, {12, 6});
  b.AddZone("left & low", {{0, 0}, {6, 0}, {6, 6}, {0, 6}});
  b.AddRectZone("right", {6, 0}, {12, 6});
  b.AddPoint("a", {1, 1}, PointKind::kLane);
  b.AddPoint("b", {5, 1}, PointKind::kIntersection);
  b.AddPoint("top", {5, 5}, PointKind::kPick);
  b.AddPoint("d", {9, 1}, PointKind::kDrop);
  b.AddPoint("p", {11, 3}, PointKind::kPark);
  b.AddPoint("ch", {9, 5}, PointKind::kCharge);
  b.AddPath("a", "b", std::nullopt, 0.0, true);
  b.AddPath("b", "top", std::nullopt, 0.0, true);
  b.AddPath("b", "d");
  b.AddPath("d", "p");
  b.AddPath("p", "ch", std::nullopt, 0.0, true);
  b.AddPath("ch", "top");
  b.AddPath("top", "ch");
  b.AddIntersection("X", {"b"}, {"a", "top"});
  b.AddStation("P1", "p", 3);
  b.AddShelf("s1", {2, 3}, {3, 5});
  b.AddShelf("s2", {7, 2}, {8, 4});
  return b;
}

WarehouseMap Build(const MapBuilder& b) {
  Result<WarehouseMap> map = b.Build();
  if (!map) ADD_FAILURE() << map.error().message;
  return std::move(map).value();
}

WarehouseMap SampleMap() { return Build(SampleBuilder()); }

TEST(MapSvgTest, DetailedRenderHasEveryElement) {
  const WarehouseMap map = SampleMap();
  SvgOptions options;
  options.show_legend = false;
  const std::string svg = RenderMapSvg(map, options);
  EXPECT_EQ(svg.rfind("<svg xmlns=\"http://www.w3.org/2000/svg\"", 0), 0u);
  EXPECT_EQ(svg.substr(svg.size() - 7), "</svg>\n");
  EXPECT_EQ(Count(svg, "<g"), Count(svg, "</g>"));
  EXPECT_EQ(Count(svg, "<rect class=\"shelf\""), 2u);
  EXPECT_EQ(Count(svg, "<polygon class=\"zone\""), 2u);
  EXPECT_EQ(Count(svg, "marker-end=\"url(#arrow)\""), 4u);  // the one-way paths
  EXPECT_EQ(Count(svg, "<line class=\"lane2\""), 3u);       // single lanes: no arrows
  EXPECT_EQ(Count(svg, "<circle class=\"pt "), 6u);
  EXPECT_EQ(Count(svg, "<circle class=\"inter-inner\""), 1u);
  EXPECT_EQ(Count(svg, "<rect class=\"approach\""), 2u);
  EXPECT_NE(svg.find(">P1 \u00d73</text>"), std::string::npos);  // station capacity
  EXPECT_NE(svg.find("S=36 m\u00b2"), std::string::npos);        // zone area
  EXPECT_NE(svg.find("left &amp; low"), std::string::npos);      // escaped
  EXPECT_NE(svg.find("<title>svg &lt;sample&gt;</title>"), std::string::npos);
  EXPECT_EQ(svg.find("<sample>"), std::string::npos);
  EXPECT_EQ(Count(svg, "class=\"pt-label\""), 6u);
  EXPECT_EQ(svg.find("class=\"legend\""), std::string::npos);
}

TEST(MapSvgTest, YAxisPointsUp) {
  const std::string svg = RenderMapSvg(SampleMap());
  // "top" (y = 5) is drawn above "b" (y = 1): smaller SVG y.
  EXPECT_LT(CircleY(svg, "top"), CircleY(svg, "b"));
  // Fixed scale: 10 px/m, 20 px margin, floor top at y = 6 -> cy = 20 + (6 - 1) * 10.
  SvgOptions options;
  options.pixels_per_metre = 10;
  const std::string fixed = RenderMapSvg(SampleMap(), options);
  EXPECT_DOUBLE_EQ(CircleY(fixed, "b"), 70.0);
  EXPECT_DOUBLE_EQ(CircleY(fixed, "top"), 30.0);
}

TEST(MapSvgTest, LegendAndLabelsAreOptional) {
  const std::string with = RenderMapSvg(SampleMap());
  EXPECT_NE(with.find("class=\"legend\""), std::string::npos);
  EXPECT_NE(with.find(">single lane (both ways)</text>"), std::string::npos);
  SvgOptions options;
  options.show_point_labels = false;
  options.show_zone_labels = false;
  const std::string without = RenderMapSvg(SampleMap(), options);
  EXPECT_EQ(without.find("class=\"pt-label\""), std::string::npos);
  EXPECT_EQ(without.find("class=\"zone-label\""), std::string::npos);
}

// Free-space regions: a dashed green polygon each, named in its title, and a legend entry; a
// map without them has neither.
TEST(MapSvgTest, FreeSpacesAreDrawnWithALegendEntry) {
  const std::string without = RenderMapSvg(SampleMap());
  EXPECT_EQ(without.find("<polygon class=\"free-space\""), std::string::npos);
  EXPECT_EQ(without.find("free space (four-wheel steer)"), std::string::npos);
  MapBuilder b = SampleBuilder();
  b.AddFreeSpace("dock & bay", {{0, 0}, {6, 0}, {6, 2}, {0, 2}});
  const std::string with = RenderMapSvg(Build(b));
  EXPECT_EQ(Count(with, "<polygon class=\"free-space\""), 1u);
  EXPECT_NE(with.find("<title>free space dock &amp; bay</title>"), std::string::npos);
  EXPECT_NE(with.find(">free space (four-wheel steer)</text>"), std::string::npos);
  // Drawn over the zones, under the shelves.
  EXPECT_LT(with.find("class=\"zones\""), with.find("class=\"free-spaces\""));
  EXPECT_LT(with.find("class=\"free-spaces\""), with.find("class=\"shelves\""));
}

TEST(MapSvgTest, CompactStyleAboveTheDetailLimit) {
  SvgOptions options;
  options.detail_limit = 3;
  options.show_legend = false;
  const std::string svg = RenderMapSvg(SampleMap(), options);
  EXPECT_EQ(Count(svg, "marker-end"), 0u);
  EXPECT_EQ(Count(svg, "<circle class=\"pt "), 0u);
  EXPECT_NE(svg.find("<g class=\"world\" transform=\"matrix("), std::string::npos);
  EXPECT_NE(svg.find(" 0 0 -"), std::string::npos);  // negative y scale: y up
  EXPECT_EQ(Count(svg, "<path class=\"shelf\""), 1u);
  EXPECT_EQ(Count(svg, "<path class=\"pt "), 6u);  // one per kind
  EXPECT_EQ(Count(svg, "<g"), Count(svg, "</g>"));
}

TEST(MapSvgTest, RendersLorrFloors) {
  const std::string dir = DISPATCH_SHARED_DIR "/benchmarks/lorr2024/example_problems/";
  Result<WarehouseMap> small = LoadMovingAiMapFile(dir + "random.domain/maps/random-32-32-20.map");
  ASSERT_TRUE(small.ok()) << small.error().message;
  SvgOptions no_legend;
  no_legend.show_legend = false;
  const std::string small_svg = RenderMapSvg(*small, no_legend);
  EXPECT_EQ(small_svg.rfind("<svg", 0), 0u);
  EXPECT_EQ(Count(small_svg, "<circle class=\"pt "), small->point_count());
  EXPECT_EQ(Count(small_svg, "<line class=\"lane2\""), small->paths().size());
  EXPECT_EQ(Count(small_svg, "marker-end"), 0u);  // all single lanes: no arrows

  Result<WarehouseMap> large =
      LoadMovingAiMapFile(dir + "warehouse.domain/maps/warehouse_large.map");
  ASSERT_TRUE(large.ok()) << large.error().message;
  const std::string svg = RenderMapSvg(*large);
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_EQ(svg.substr(svg.size() - 7), "</svg>\n");
  EXPECT_NE(svg.find("class=\"world\""), std::string::npos);
  EXPECT_LT(svg.size(), 4u * 1024 * 1024) << "compact style should stay small";
  std::printf("warehouse_large.svg: %zu bytes\n", svg.size());
}

}  // namespace
}  // namespace dispatch::engine
