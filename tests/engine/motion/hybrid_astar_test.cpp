// The improved hybrid A* (engine/motion/hybrid_astar.h) on the narrow-area floor
// (engine/motion/narrow_floor.h) and on small grids.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <numbers>
#include <random>

#include "engine/motion/hybrid_astar.h"
#include "engine/motion/motion_path_check.h"
#include "engine/motion/narrow_floor.h"

namespace dispatch::engine {
namespace {

constexpr double kPi = std::numbers::pi;

bool Uses(const MotionPath& path, std::initializer_list<MotionMode> modes) {
  return std::any_of(path.modes.begin(), path.modes.end(), [&](MotionMode m) {
    return std::find(modes.begin(), modes.end(), m) != modes.end();
  });
}

class NarrowFloorTest : public ::testing::Test {
 protected:
  NarrowFloorTest() : floor_(BuildNarrowFloor()), checker_(floor_.grid, floor_.footprint) {
    options_.min_turn_radius = floor_.min_turn_radius;
  }
  HybridAStarOptions Baseline() const {
    HybridAStarOptions o = options_;
    o.allow_crab = false;
    o.allow_spin = false;
    return o;
  }
  void ExpectValid(const MotionPath& path, const MotionPose& start, const MotionPose& goal) const {
    MotionPathCheck check;
    check.radius = floor_.min_turn_radius;
    const Status status = CheckMotionPath(checker_, path, start, goal, check);
    EXPECT_TRUE(status.ok()) << status.error().message;
    EXPECT_GT(path.nodes_expanded, 0u);
  }
  NarrowFloor floor_;
  FootprintChecker checker_;
  HybridAStarOptions options_;
};

TEST_F(NarrowFloorTest, ScenarioPosesAreFreeAndTheFeaturesAreTight) {
  for (const MotionPose& p : {floor_.crab_start, floor_.crab_goal, floor_.dead_end_start, floor_.dead_end_goal,
                              floor_.cross_start, floor_.cross_goal}) {
    EXPECT_FALSE(checker_.Collides(p)) << p.x << " " << p.y;
  }
  // The slot only fits the robot lengthwise, and the aisle is narrower than a turning circle.
  EXPECT_TRUE(checker_.Collides({floor_.crab_goal.x, floor_.crab_goal.y, kPi / 2}));
  EXPECT_TRUE(checker_.Collides({floor_.crab_goal.x + 0.15, floor_.crab_goal.y, 0.0}));
  EXPECT_LT(1.1, 2 * floor_.min_turn_radius);
  // A spin fits in the aisle.
  for (double a = 0; a < kPi; a += 0.05) EXPECT_FALSE(checker_.Collides({9.05, 4.0, a}));
}

TEST_F(NarrowFloorTest, CrossFloorQueryReachesTheHeadingGoal) {
  const Result<MotionPath> path = PlanHybridAStar(checker_, floor_.cross_start, floor_.cross_goal, options_);
  ASSERT_TRUE(path.ok()) << path.error().message;
  ExpectValid(*path, floor_.cross_start, floor_.cross_goal);
  EXPECT_GT(path->length, 5.0);
}

TEST_F(NarrowFloorTest, CrabSlotNeeds4wis) {
  const Result<MotionPath> wis = PlanHybridAStar(checker_, floor_.crab_start, floor_.crab_goal, options_);
  ASSERT_TRUE(wis.ok()) << wis.error().message;
  ExpectValid(*wis, floor_.crab_start, floor_.crab_goal);
  EXPECT_TRUE(Uses(*wis, {MotionMode::kCrabLeft}));
  const Result<MotionPath> car = PlanHybridAStar(checker_, floor_.crab_start, floor_.crab_goal, Baseline());
  ASSERT_FALSE(car.ok()) << "baseline parked with length " << car->length;
  EXPECT_EQ(car.error().code, ErrorCode::kUnreachable) << car.error().message;
}

// From beyond the analytic range, facing away: turn round in the 1.4 m corridor (too narrow
// for a U-turn on arcs), drive back and crab into the slot.
TEST_F(NarrowFloorTest, CrabSlotFromTheFarEndFacingAway) {
  const MotionPose start{10.8, 0.8, 0.0};
  const Result<MotionPath> wis = PlanHybridAStar(checker_, start, floor_.crab_goal, options_);
  ASSERT_TRUE(wis.ok()) << wis.error().message;
  ExpectValid(*wis, start, floor_.crab_goal);
  EXPECT_GT(wis->nodes_expanded, 1u);
  EXPECT_TRUE(Uses(*wis, {MotionMode::kCrabLeft}));
}

TEST_F(NarrowFloorTest, DeadEndAisleIsLeftBySpinningOrReversing) {
  const Result<MotionPath> wis = PlanHybridAStar(checker_, floor_.dead_end_start, floor_.dead_end_goal, options_);
  ASSERT_TRUE(wis.ok()) << wis.error().message;
  ExpectValid(*wis, floor_.dead_end_start, floor_.dead_end_goal);
  EXPECT_TRUE(Uses(*wis, {MotionMode::kSpinLeft, MotionMode::kSpinRight, MotionMode::kReverse,
                          MotionMode::kArcReverseLeft, MotionMode::kArcReverseRight}));
  const Result<MotionPath> car = PlanHybridAStar(checker_, floor_.dead_end_start, floor_.dead_end_goal, Baseline());
  ASSERT_TRUE(car.ok()) << car.error().message;  // it can back out
  ExpectValid(*car, floor_.dead_end_start, floor_.dead_end_goal);
  EXPECT_FALSE(Uses(*car, {MotionMode::kSpinLeft, MotionMode::kSpinRight, MotionMode::kCrabLeft, MotionMode::kCrabRight}));
}

// Eq. (5) with the seed's plain |dx| + |dy| still finds valid paths (with many more
// expansions on the cross-floor query: the corridor's west end is a local minimum of it).
TEST_F(NarrowFloorTest, PlainManhattanHeuristicAlsoWorks) {
  HybridAStarOptions plain = options_;
  plain.manhattan_through_free_cells = false;
  const Result<MotionPath> path = PlanHybridAStar(checker_, floor_.cross_start, floor_.cross_goal, plain);
  ASSERT_TRUE(path.ok()) << path.error().message;
  ExpectValid(*path, floor_.cross_start, floor_.cross_goal);
  const Result<MotionPath> informed = PlanHybridAStar(checker_, floor_.cross_start, floor_.cross_goal, options_);
  ASSERT_TRUE(informed.ok()) << informed.error().message;
  EXPECT_LT(informed->nodes_expanded * 10, path->nodes_expanded);
}

TEST_F(NarrowFloorTest, ZeroDeadlineStops) {
  options_.limits.stop = DeadlineCheck(std::chrono::nanoseconds(0));
  const Result<MotionPath> path = PlanHybridAStar(checker_, floor_.cross_start, floor_.cross_goal, options_);
  ASSERT_FALSE(path.ok());
  EXPECT_EQ(path.error().code, ErrorCode::kFailedPrecondition);
}

TEST_F(NarrowFloorTest, CancelStopsAndExpansionBoundStops) {
  int polls = 0;
  bool cancelled = false;
  options_.limits.stop = DeadlineCheck(std::chrono::hours(1), [&] {
    if (++polls == 20) cancelled = true;
    return cancelled;
  });
  const Result<MotionPath> path = PlanHybridAStar(checker_, floor_.cross_start, floor_.cross_goal, options_);
  ASSERT_FALSE(path.ok());
  EXPECT_EQ(path.error().code, ErrorCode::kFailedPrecondition);
  EXPECT_EQ(polls, 20);
  options_.limits = {};
  options_.limits.max_expansions = 10;
  const Result<MotionPath> bounded = PlanHybridAStar(checker_, floor_.cross_start, floor_.cross_goal, options_);
  ASSERT_FALSE(bounded.ok());
  EXPECT_EQ(bounded.error().code, ErrorCode::kFailedPrecondition);
  options_.limits = {};
  EXPECT_TRUE(PlanHybridAStar(checker_, floor_.cross_start, floor_.cross_goal, options_).ok());
}

TEST_F(NarrowFloorTest, SameInputSamePath) {
  const Result<MotionPath> a = PlanHybridAStar(checker_, floor_.cross_start, floor_.cross_goal, options_);
  const Result<MotionPath> b = PlanHybridAStar(checker_, floor_.cross_start, floor_.cross_goal, options_);
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(a->poses.size(), b->poses.size());
  EXPECT_EQ(a->nodes_expanded, b->nodes_expanded);
  for (std::size_t i = 0; i < a->poses.size(); ++i) {
    EXPECT_EQ(a->poses[i].x, b->poses[i].x);
    EXPECT_EQ(a->poses[i].y, b->poses[i].y);
    EXPECT_EQ(a->poses[i].theta, b->poses[i].theta);
  }
  EXPECT_EQ(a->modes, b->modes);
}

TEST_F(NarrowFloorTest, CollidingStartOrGoalIsInvalid) {
  const Result<MotionPath> path = PlanHybridAStar(checker_, {0.05, 0.05, 0.0}, floor_.cross_goal, options_);
  ASSERT_FALSE(path.ok());
  EXPECT_EQ(path.error().code, ErrorCode::kInvalidArgument);
  const Result<MotionPath> goal = PlanHybridAStar(checker_, floor_.cross_start, {2.0, 4.0, 0.0}, options_);
  ASSERT_FALSE(goal.ok());
  EXPECT_EQ(goal.error().code, ErrorCode::kInvalidArgument);
}

// Model check on random floors: whatever the planner returns passes CheckMotionPath (free,
// drivable in its modes, at the goal), for 4WIS and the baseline.
TEST(HybridAStarTest, RandomFloorsGiveValidPaths) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> pos(0.5, 4.5);
  std::uniform_real_distribution<double> ang(-kPi, kPi);
  int found = 0;
  for (int round = 0; round < 12; ++round) {
    OccupancyGrid grid(50, 50, 0.1);
    for (int k = 0; k < 12; ++k) {
      const double x = pos(rng), y = pos(rng);
      grid.SetRect({x, y}, {x + 0.3, y + 0.3}, true);
    }
    grid.ComputeClearance();
    const FootprintChecker checker(grid, {0.6, 0.4, 0.0});
    auto free_pose = [&] {
      MotionPose p{pos(rng), pos(rng), ang(rng)};
      while (checker.Collides(p)) p = {pos(rng), pos(rng), ang(rng)};
      return p;
    };
    const MotionPose start = free_pose();
    const MotionPose goal = free_pose();
    for (const bool wis : {true, false}) {
      HybridAStarOptions o;
      o.min_turn_radius = 0.6;
      o.allow_crab = o.allow_spin = wis;
      o.limits.max_expansions = 20000;
      const Result<MotionPath> path = PlanHybridAStar(checker, start, goal, o);
      if (!path.ok()) {
        EXPECT_NE(path.error().code, ErrorCode::kInvalidArgument) << path.error().message;
        continue;
      }
      ++found;
      MotionPathCheck check;
      check.radius = 0.6;
      const Status valid = CheckMotionPath(checker, *path, start, goal, check);
      EXPECT_TRUE(valid.ok()) << round << (wis ? " 4wis: " : " baseline: ") << valid.error().message;
      if (!wis) {
        EXPECT_FALSE(Uses(*path, {MotionMode::kCrabLeft, MotionMode::kCrabRight, MotionMode::kSpinLeft,
                                  MotionMode::kSpinRight}));
      }
    }
  }
  EXPECT_GE(found, 12);
}

TEST(HybridAStarTest, AdaptiveXiShrinksTowardsTheGoal) {
  HybridAStarOptions o;
  EXPECT_EQ(HeuristicWeight(o, 12.0), 1.5);
  EXPECT_EQ(HeuristicWeight(o, 6.0), 1.5);
  EXPECT_EQ(HeuristicWeight(o, 5.0), 1.2);
  EXPECT_EQ(HeuristicWeight(o, 2.9), 1.0);
  EXPECT_EQ(HeuristicWeight(o, 0.0), 1.0);
  o.adaptive_xi = false;
  o.fixed_xi = 1.5;
  EXPECT_EQ(HeuristicWeight(o, 12.0), 1.5);
  o.adaptive_xi = true;
  o.xi_bands = {{1.0, 1.0}, {2.0, 2.0}};
  OccupancyGrid grid(10, 10, 0.1);
  const FootprintChecker checker(grid, {0.2, 0.2, 0.0});
  EXPECT_EQ(PlanHybridAStar(checker, {0.5, 0.5, 0}, {0.6, 0.5, 0}, o).error().code, ErrorCode::kInvalidArgument);
}

// In open space near the goal the analytic expansion finishes at once: straight ahead by
// Reeds-Shepp, sideways by crabbing (4WIS) and by a longer Reeds-Shepp path for the baseline.
TEST(HybridAStarTest, AnalyticExpansionInOpenSpace) {
  OccupancyGrid grid(60, 60, 0.1);
  grid.ComputeClearance();
  const FootprintChecker checker(grid, {0.8, 0.5, 0.0});
  HybridAStarOptions o;
  const Result<MotionPath> ahead = PlanHybridAStar(checker, {1.0, 3.0, 0.0}, {3.0, 3.0, 0.0}, o);
  ASSERT_TRUE(ahead.ok()) << ahead.error().message;
  EXPECT_EQ(ahead->finish, "reeds_shepp");
  EXPECT_NEAR(ahead->length, 2.0, 1e-6);
  EXPECT_EQ(ahead->nodes_expanded, 1u);
  const Result<MotionPath> side = PlanHybridAStar(checker, {3.0, 2.0, 0.0}, {3.0, 3.0, 0.0}, o);
  ASSERT_TRUE(side.ok()) << side.error().message;
  EXPECT_EQ(side->finish, "crab");
  EXPECT_NEAR(side->length, 1.0, 1e-6);
  EXPECT_EQ(side->switches, 0);
  o.allow_crab = false;
  o.allow_spin = false;
  const Result<MotionPath> car = PlanHybridAStar(checker, {3.0, 2.0, 0.0}, {3.0, 3.0, 0.0}, o);
  ASSERT_TRUE(car.ok()) << car.error().message;
  EXPECT_EQ(car->finish, "reeds_shepp");
  EXPECT_GT(car->length, 2.0);
  const Status valid = CheckMotionPath(checker, *car, {3.0, 2.0, 0.0}, {3.0, 3.0, 0.0});
  EXPECT_TRUE(valid.ok()) << valid.error().message;
}

}  // namespace
}  // namespace dispatch::engine
