// Reeds-Shepp paths (engine/motion/reeds_shepp.h).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>
#include <numbers>
#include <random>

#include "engine/motion/reeds_shepp.h"

namespace dispatch::engine {
namespace {

constexpr double kPi = std::numbers::pi;

MotionPose End(const MotionPose& start, const RsPath& path, double radius) {
  MotionPath out;
  SampleReedsShepp(start, path, radius, 0.05, out);
  return out.poses.back();
}

void ExpectNear(const MotionPose& a, const MotionPose& b, double tol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(WrapHeading(a.theta - b.theta), 0.0, tol);
}

TEST(ReedsSheppTest, StraightLineIsOneForwardSegment) {
  const RsPath path = ShortestReedsShepp({1, 1, kPi / 4}, {1 + 3 / std::sqrt(2.0), 1 + 3 / std::sqrt(2.0), kPi / 4}, 0.8);
  ASSERT_EQ(path.segments.size(), 1u);
  EXPECT_EQ(RsSegmentMode(path.segments[0]), MotionMode::kForward);
  EXPECT_NEAR(path.length, 3.0, 1e-9);
}

TEST(ReedsSheppTest, PureReverseIsOneBackwardSegment) {
  const RsPath path = ShortestReedsShepp({0, 0, 0}, {-2, 0, 0}, 1.0);
  ASSERT_EQ(path.segments.size(), 1u);
  EXPECT_EQ(RsSegmentMode(path.segments[0]), MotionMode::kReverse);
  EXPECT_NEAR(path.length, 2.0, 1e-9);
}

TEST(ReedsSheppTest, QuarterTurnIsOneArc) {
  const RsPath path = ShortestReedsShepp({0, 0, 0}, {1, 1, kPi / 2}, 1.0);
  ASSERT_EQ(path.segments.size(), 1u);
  EXPECT_EQ(RsSegmentMode(path.segments[0]), MotionMode::kArcForwardLeft);
  EXPECT_NEAR(path.length, kPi / 2, 1e-9);
}

// L+ (pi/2) S+ (1) R+ (pi/2) ends at (2, 3, 0) for r = 1: the CSC word is among the paths,
// with its length pi + 1, and nothing returned is longer than needed to be shortest.
TEST(ReedsSheppTest, KnownCscCase) {
  const std::vector<RsPath> paths = ReedsSheppPaths({0, 0, 0}, {2, 3, 0}, 1.0);
  ASSERT_FALSE(paths.empty());
  bool found = false;
  for (const RsPath& p : paths) {
    if (p.segments.size() == 3 && p.segments[0].type == 'L' && p.segments[1].type == 'S' &&
        p.segments[2].type == 'R' && std::abs(p.length - (kPi + 1)) < 1e-9) {
      found = true;
      EXPECT_NEAR(p.segments[0].length, kPi / 2, 1e-9);
      EXPECT_NEAR(p.segments[1].length, 1.0, 1e-9);
      EXPECT_NEAR(p.segments[2].length, kPi / 2, 1e-9);
    }
  }
  EXPECT_TRUE(found);
  EXPECT_LE(paths.front().length, kPi + 1 + 1e-9);
  for (std::size_t k = 1; k < paths.size(); ++k) EXPECT_LE(paths[k - 1].length, paths[k].length);
}

// Every returned path ends at the goal; the shortest is no shorter than the straight-line
// distance, scales with the radius, and is the same for mirrored and time-flipped goals.
TEST(ReedsSheppTest, RandomQueriesEndAtGoalAndAreSymmetric) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> pos(-4.0, 4.0);
  std::uniform_real_distribution<double> ang(-kPi, kPi);
  for (int k = 0; k < 500; ++k) {
    const MotionPose start{pos(rng), pos(rng), ang(rng)};
    const MotionPose goal{pos(rng), pos(rng), ang(rng)};
    const std::vector<RsPath> paths = ReedsSheppPaths(start, goal, 0.8);
    ASSERT_FALSE(paths.empty()) << k;
    for (const RsPath& p : paths) ExpectNear(End(start, p, 0.8), goal, 1e-6);
    EXPECT_GE(paths.front().length + 1e-9, std::hypot(goal.x - start.x, goal.y - start.y));
    // In the start's frame: (x, y, phi); mirror (x, -y, -phi) and time-flip (-x, y, -phi).
    const double c = std::cos(start.theta), s = std::sin(start.theta);
    const double x = c * (goal.x - start.x) + s * (goal.y - start.y);
    const double y = -s * (goal.x - start.x) + c * (goal.y - start.y);
    const double phi = WrapHeading(goal.theta - start.theta);
    const double len = paths.front().length;
    EXPECT_NEAR(ShortestReedsShepp({0, 0, 0}, {x, -y, -phi}, 0.8).length, len, 1e-7);
    EXPECT_NEAR(ShortestReedsShepp({0, 0, 0}, {-x, y, -phi}, 0.8).length, len, 1e-7);
    EXPECT_NEAR(ShortestReedsShepp({0, 0, 0}, {2 * x, 2 * y, phi}, 1.6).length, 2 * len, 1e-6);
  }
}

// Every family's formulas produce valid paths (candidates that miss the goal are dropped, so
// a wrong formula would show as a family that never appears).
TEST(ReedsSheppTest, EveryFamilyYieldsPaths) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> pos(-3.0, 3.0);
  std::uniform_real_distribution<double> ang(-kPi, kPi);
  std::map<std::string, int> seen;
  for (int k = 0; k < 2000; ++k) {
    for (const RsPath& p : ReedsSheppPaths({0, 0, 0}, {pos(rng), pos(rng), ang(rng)}, 1.0)) {
      std::string word;
      for (const RsSegment& seg : p.segments) word += seg.type == 'S' ? 'S' : 'C';
      ++seen[word];
    }
  }
  for (const char* family : {"CSC", "CCC", "CCCC", "CCSC", "CSCC", "CCSCC"}) {
    EXPECT_GT(seen[family], 0) << family;
  }
}

TEST(ReedsSheppTest, SamplesAreCloseAndModesMatchSegments) {
  const MotionPose start{0, 0, 0};
  const RsPath path = ShortestReedsShepp(start, {0.5, 1.0, kPi}, 0.8);
  MotionPath out;
  SampleReedsShepp(start, path, 0.8, 0.05, out);
  ASSERT_EQ(out.modes.size() + 1, out.poses.size());
  for (std::size_t i = 0; i + 1 < out.poses.size(); ++i) {
    EXPECT_LE(std::hypot(out.poses[i + 1].x - out.poses[i].x, out.poses[i + 1].y - out.poses[i].y), 0.05 + 1e-9);
  }
  Summarize(out);
  EXPECT_NEAR(out.length, path.length, 1e-3);  // chords of fine arcs
}

}  // namespace
}  // namespace dispatch::engine
