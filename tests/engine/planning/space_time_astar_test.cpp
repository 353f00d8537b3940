#include "engine/planning/space_time_astar.h"

#include <gtest/gtest.h>

#include "grid_instances.h"

namespace dispatch::engine {
namespace {

using testing_grid::Cell;
using testing_grid::Grid;

const std::vector<std::string> kRow = {"....."};  // 0 1 2 3 4

Result<AgentSearch> Plan(const MapfGraph& g, PointId from, PointId to, const std::vector<PathConstraint>& c,
                         const PlanLimits& limits = {}) {
  return PlanAgent(g, g.StepsTo(to), from, to, c, limits);
}

TEST(SpaceTimeAStarTest, WithoutConstraintsThePathIsAShortestOne) {
  const std::vector<std::string> rows = {"....", ".@@.", "...."};
  const MapfGraph g = Grid(rows);
  const auto found = Plan(g, Cell(rows, 1, 0), Cell(rows, 1, 3), {});
  ASSERT_TRUE(found.ok()) << found.error().message;
  EXPECT_EQ(PathCost(found.value().path), 5);
  EXPECT_TRUE(CheckPaths(g, {{Cell(rows, 1, 0), Cell(rows, 1, 3)}}, {found.value().path}).ok());
  EXPECT_EQ(Plan(g, 2, 2, {}).value().path, TimedPath{2});
}

TEST(SpaceTimeAStarTest, AVertexBannedAtAStepIsWaitedOut) {
  const MapfGraph g = Grid(kRow);
  const auto found = Plan(g, 0, 4, {PathConstraint::Vertex(2, 2)});
  ASSERT_TRUE(found.ok());
  const TimedPath& p = found.value().path;
  EXPECT_EQ(PathCost(p), 5);  // one wait somewhere before 2
  EXPECT_NE(PositionAt(p, 2), 2);
}

TEST(SpaceTimeAStarTest, ABannedMoveIsNotTakenThen) {
  const MapfGraph g = Grid(kRow);
  const auto found = Plan(g, 0, 4, {PathConstraint::Move(1, 2, 2)});  // not 1 -> 2 arriving at step 2
  ASSERT_TRUE(found.ok());
  const TimedPath& p = found.value().path;
  EXPECT_EQ(PathCost(p), 5);
  EXPECT_FALSE(PositionAt(p, 1) == 1 && PositionAt(p, 2) == 2);
}

TEST(SpaceTimeAStarTest, ALaterBanOnTheGoalKeepsTheAgentFromStayingThereEarlier) {
  const MapfGraph g = Grid(kRow);
  const auto found = Plan(g, 0, 2, {PathConstraint::Vertex(2, 6)});
  ASSERT_TRUE(found.ok());
  const TimedPath& p = found.value().path;
  EXPECT_EQ(p.back(), 2);
  EXPECT_EQ(PathCost(p), 7);  // arrives (for good) after step 6
  EXPECT_NE(PositionAt(p, 6), 2);
}

TEST(SpaceTimeAStarTest, SettlingIsBoundedFromBelowAndAbove) {
  const MapfGraph g = Grid(kRow);
  const auto later = Plan(g, 0, 2, {PathConstraint::FinishAfter(4)});
  ASSERT_TRUE(later.ok());
  EXPECT_EQ(PathCost(later.value().path), 5);
  EXPECT_EQ(PathCost(Plan(g, 0, 2, {PathConstraint::FinishBy(3)}).value().path), 2);
  // Two steps away cannot be settled by step 1, nor between steps 4 and 4.
  EXPECT_EQ(Plan(g, 0, 2, {PathConstraint::FinishBy(1)}).error().code, ErrorCode::kUnreachable);
  EXPECT_EQ(Plan(g, 0, 2, {PathConstraint::FinishAfter(4), PathConstraint::FinishBy(4)}).error().code,
            ErrorCode::kUnreachable);
}

TEST(SpaceTimeAStarTest, AVertexKeptAwayFromIsPassedBeforeOrNever) {
  const std::vector<std::string> rows = {"...", "..."};  // 0 1 2 / 3 4 5
  const MapfGraph g = Grid(rows);
  const auto found = Plan(g, 0, 2, {PathConstraint::AwayFrom(1, 0)});
  ASSERT_TRUE(found.ok());
  EXPECT_EQ(PathCost(found.value().path), 4);  // round by the lower row
  for (PointId v : found.value().path) EXPECT_NE(v, 1);
  EXPECT_EQ(PathCost(Plan(g, 0, 2, {PathConstraint::AwayFrom(1, 3)}).value().path), 2);  // through before
  EXPECT_EQ(Plan(g, 0, 2, {PathConstraint::AwayFrom(2, 9)}).error().code, ErrorCode::kUnreachable);
}

TEST(SpaceTimeAStarTest, NoPathIsUnreachableAndABannedStartToo) {
  const std::vector<std::string> rows = {".@."};
  const MapfGraph g = Grid(rows);
  EXPECT_EQ(Plan(g, 0, 2, {}).error().code, ErrorCode::kUnreachable);
  EXPECT_EQ(Plan(Grid(kRow), 0, 4, {PathConstraint::Vertex(0, 0)}).error().code, ErrorCode::kUnreachable);
  // Every step at the only way through is banned for a while: the agent waits them out.
  std::vector<PathConstraint> wall;
  for (int t = 0; t < 20; ++t) wall.push_back(PathConstraint::Vertex(2, t));
  const auto found = Plan(Grid(kRow), 0, 4, wall);
  ASSERT_TRUE(found.ok());
  EXPECT_EQ(PathCost(found.value().path), 22);
}

TEST(SpaceTimeAStarTest, TheLimitsStopTheSearch) {
  const MapfGraph g = Grid({"..........", "..........", ".........."});
  PlanLimits few;
  few.max_expansions = 3;
  EXPECT_EQ(Plan(g, 0, 29, {}, few).error().code, ErrorCode::kFailedPrecondition);
  PlanLimits cancelled;
  cancelled.stop = [] { return true; };
  std::vector<PathConstraint> wall;  // long enough to reach the first poll
  for (int t = 0; t < 400; ++t) wall.push_back(PathConstraint::Vertex(29, t));
  EXPECT_EQ(Plan(g, 0, 29, wall, cancelled).error().code, ErrorCode::kFailedPrecondition);
  EXPECT_FALSE(Plan(g, 0, 99, {}).ok());  // not a vertex
}

}  // namespace
}  // namespace dispatch::engine
