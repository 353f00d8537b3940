#include "engine/lifelong/grid_motion.h"

#include <gtest/gtest.h>

#include "engine/io/movingai_map.h"

namespace dispatch::engine {
namespace {

// 3 x 4:  ....
//         .@..
//         ....
LorrGrid SmallGrid() {
  MovingAiImportReport report;
  auto map = ParseMovingAiMap("type octile\nheight 3\nwidth 4\nmap\n....\n.@..\n....\n", "small", {}, &report);
  EXPECT_TRUE(map.ok());
  auto grid = LorrGrid::FromMap(std::make_shared<const WarehouseMap>(std::move(map).value()), 3, 4);
  EXPECT_TRUE(grid.ok());
  return std::move(grid).value();
}

TEST(GridMotionTest, ForwardFollowsTheDirectionAndTurnsAreQuarterTurns) {
  const LorrGrid grid = SmallGrid();
  EXPECT_EQ(Apply(grid, {0, 0}, GridAction::kForward), (GridPose{1, 0}));   // east
  EXPECT_EQ(Apply(grid, {0, 1}, GridAction::kForward), (GridPose{4, 1}));   // south
  EXPECT_EQ(Apply(grid, {0, 0}, GridAction::kClockwise), (GridPose{0, 1}));  // E -> S
  EXPECT_EQ(Apply(grid, {0, 0}, GridAction::kCounterClockwise), (GridPose{0, 3}));  // E -> N
  EXPECT_EQ(Apply(grid, {4, 0}, GridAction::kForward), (GridPose{4, 0}));  // into the block: stays
  EXPECT_EQ(TurnsBetween(0, 2), 2);
  EXPECT_EQ(TurnTowards(0, 3), GridAction::kCounterClockwise);
  EXPECT_EQ(TurnTowards(0, 2), GridAction::kClockwise);
}

TEST(GridMotionTest, TheJointStepRulesAreTheCompetitions) {
  const LorrGrid grid = SmallGrid();
  using A = GridAction;
  // Into the blocked cell 5, and off the grid.
  EXPECT_EQ(CheckJointStep(grid, {{4, 0}}, {A::kForward}).size(), 1u);
  EXPECT_EQ(CheckJointStep(grid, {{3, 0}}, {A::kForward}).size(), 1u);
  // Two robots into cell 1.
  auto vertex = CheckJointStep(grid, {{0, 0}, {2, 2}}, {A::kForward, A::kForward});
  ASSERT_EQ(vertex.size(), 1u);
  EXPECT_EQ(vertex[0].other, 0);
  // A swap of cells 0 and 1.
  EXPECT_EQ(CheckJointStep(grid, {{0, 0}, {1, 2}}, {A::kForward, A::kForward}).size(), 1u);
  // Following is legal: 0 -> 1 while 1 -> 2.
  EXPECT_TRUE(CheckJointStep(grid, {{0, 0}, {1, 0}}, {A::kForward, A::kForward}).empty());
  // ...but not into a robot that stays (it turns).
  EXPECT_EQ(CheckJointStep(grid, {{0, 0}, {1, 0}}, {A::kForward, A::kClockwise}).size(), 1u);
  // A closed cycle of four round the block at cells 2, 3, 7, 6 is legal.
  EXPECT_TRUE(CheckJointStep(grid, {{2, 0}, {3, 1}, {7, 2}, {6, 3}},
                             {A::kForward, A::kForward, A::kForward, A::kForward})
                  .empty());
}

}  // namespace
}  // namespace dispatch::engine
