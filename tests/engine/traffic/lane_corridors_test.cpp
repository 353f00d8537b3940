// Lane corridors: chains of bidirectional single lanes through degree-2 points.
#include "engine/traffic/lane_corridors.h"

#include <gtest/gtest.h>

#include "engine/map/map_builder.h"

namespace dispatch::engine {
namespace {

WarehouseMap Build(MapBuilder& b) {
  MapBuildOptions options;
  options.check_service_connectivity = false;
  auto map = b.Build(options);
  if (!map.ok()) throw std::runtime_error(map.error().message);
  return std::move(map).value();
}

// J1 - a - b - J2 single lanes, plus spurs J1-x, J1-y, J2-z (so J1 and J2 are junctions),
// J2-v, and a one-way path z -> w.
TEST(LaneCorridorsTest, ChainsThroughDegreeTwoPoints) {
  MapBuilder b("chain");
  b.SetFloor({-1, -1}, {10, 10});
  b.AddRectZone("z0", {-1, -1}, {10, 10});
  for (auto [n, x, y] : {std::tuple{"J1", 0.0, 0.0}, {"a", 1.0, 0.0}, {"b", 2.0, 0.0},
                         {"J2", 3.0, 0.0}, {"x", 0.0, 1.0}, {"y", 0.0, -1.0}, {"z", 3.0, 1.0},
                         {"w", 3.0, 2.0}, {"v", 4.0, 0.0}}) {
    b.AddPoint(n, {x, y}, PointKind::kLane);
  }
  for (auto [f, t] : {std::pair{"J1", "a"}, {"a", "b"}, {"b", "J2"}, {"J1", "x"}, {"J1", "y"},
                      {"J2", "z"}, {"J2", "v"}}) {
    b.AddPath(f, t, std::nullopt, 0.0, true);
  }
  b.AddPath("z", "w");
  const WarehouseMap map = Build(b);
  const LaneCorridors lanes = BuildLaneCorridors(map);
  const PointId j1 = *map.FindPoint("J1"), a = *map.FindPoint("a"), bb = *map.FindPoint("b"),
                j2 = *map.FindPoint("J2"), z = *map.FindPoint("z");
  const ArcId ab = *map.FindArc(a, bb), ba = *map.FindArc(bb, a);
  const int c = lanes.CorridorOfArc(map, ab);
  ASSERT_GE(c, 0);
  EXPECT_EQ(lanes.CorridorOfArc(map, *map.FindArc(j1, a)), c);
  EXPECT_EQ(lanes.CorridorOfArc(map, *map.FindArc(bb, j2)), c);
  EXPECT_EQ(lanes.corridors[static_cast<std::size_t>(c)].paths.size(), 3u);
  EXPECT_EQ(lanes.interior_of[static_cast<std::size_t>(a)], c);
  EXPECT_EQ(lanes.interior_of[static_cast<std::size_t>(bb)], c);
  EXPECT_EQ(lanes.interior_of[static_cast<std::size_t>(j1)], -1);
  EXPECT_EQ(lanes.interior_of[static_cast<std::size_t>(j2)], -1);
  EXPECT_EQ(lanes.Direction(map, ab), -lanes.Direction(map, ba));
  EXPECT_EQ(lanes.Direction(map, ab), lanes.Direction(map, *map.FindArc(j1, a)));
  // Spurs are corridors of their own (z has degree 2 but its one-way path ends the chain).
  EXPECT_NE(lanes.CorridorOfArc(map, *map.FindArc(j2, z)), c);
  EXPECT_EQ(lanes.interior_of[static_cast<std::size_t>(z)], -1);
  EXPECT_EQ(lanes.CorridorOfArc(map, *map.FindArc(z, *map.FindPoint("w"))), -1);
  // Every single-lane path is in exactly one corridor.
  std::size_t in_corridors = 0;
  for (const LaneCorridor& k : lanes.corridors) in_corridors += k.paths.size();
  EXPECT_EQ(in_corridors, 7u);
}

TEST(LaneCorridorsTest, RingIsOneCorridor) {
  MapBuilder b("ring");
  b.SetFloor({-1, -1}, {3, 3});
  b.AddRectZone("z0", {-1, -1}, {3, 3});
  b.AddPoint("p", {0, 0}, PointKind::kLane);
  b.AddPoint("q", {2, 0}, PointKind::kLane);
  b.AddPoint("r", {2, 2}, PointKind::kLane);
  b.AddPoint("s", {0, 2}, PointKind::kLane);
  for (auto [f, t] : {std::pair{"p", "q"}, {"q", "r"}, {"r", "s"}, {"s", "p"}}) {
    b.AddPath(f, t, std::nullopt, 0.0, true);
  }
  const WarehouseMap map = Build(b);
  const LaneCorridors lanes = BuildLaneCorridors(map);
  ASSERT_EQ(lanes.corridors.size(), 1u);
  EXPECT_EQ(lanes.corridors[0].paths.size(), 4u);
  EXPECT_EQ(lanes.corridors[0].points.front(), lanes.corridors[0].points.back());
  for (std::size_t p = 0; p < map.point_count(); ++p) EXPECT_EQ(lanes.interior_of[p], 0);
  const LaneCorridor& c = lanes.corridors[0];
  for (std::size_t k = 0; k < c.paths.size(); ++k) {
    const ArcId a = *map.FindArc(c.points[k], c.points[k + 1]);
    EXPECT_EQ(lanes.Direction(map, a), 1) << k;
  }
}

}  // namespace
}  // namespace dispatch::engine
