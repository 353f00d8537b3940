// SVG rendering of motion paths (engine/io/motion_svg.h): grid runs, footprints every
// footprint_every metres, y up, escaping.
#include <gtest/gtest.h>

#include <string>

#include "engine/io/motion_svg.h"

namespace dispatch::engine {
namespace {

std::size_t Count(const std::string& s, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = s.find(what); at != std::string::npos; at = s.find(what, at + 1)) ++n;
  return n;
}

MotionPath StraightEast(double from_x, double y, double metres) {
  MotionPath p;
  for (int k = 0; k <= static_cast<int>(metres / 0.05 + 0.5); ++k) {
    p.poses.push_back({from_x + 0.05 * k, y, 0.0});
    if (k > 0) p.modes.push_back(MotionMode::kForward);
  }
  return p;
}

TEST(MotionSvgTest, GridRunsPathsAndFootprintsEveryHalfMetre) {
  OccupancyGrid grid(40, 20, 0.1);  // 4 m x 2 m
  grid.SetRect({0.0, 0.0}, {4.0, 0.1}, true);  // the bottom row: one run
  grid.SetRect({2.0, 1.5}, {2.2, 1.7}, true);  // a 2 x 2 block: two runs
  const std::string svg = RenderMotionSvg(
      grid, {{"east <fast>", "#123456", StraightEast(0.5, 1.0, 2.0), Footprint{0.8, 0.5, 0.0}}}, {});
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_EQ(Count(svg, "class=\"grid-cell\""), 3u);
  EXPECT_EQ(Count(svg, "class=\"path\""), 1u);
  EXPECT_EQ(Count(svg, "class=\"footprint\""), 5u);  // 0, 0.5, 1.0, 1.5, 2.0 m
  EXPECT_NE(svg.find("east &lt;fast&gt;"), std::string::npos);
  EXPECT_EQ(svg.find("<fast>"), std::string::npos);
  // y up: the path at y = 1 m on a 2 m floor is drawn at 10 + (2 - 1) * 80 = 90 px; it starts
  // at x = 10 + 0.5 * 80 = 50 px.
  EXPECT_NE(svg.find("points=\"50.0,90.0 "), std::string::npos);
  // The bottom row (y 0 - 0.1 m) is at the bottom of the picture: 10 + 1.9 * 80 = 162 px.
  EXPECT_NE(svg.find("x=\"10.0\" y=\"162.0\" width=\"320.0\""), std::string::npos);
}

}  // namespace
}  // namespace dispatch::engine
