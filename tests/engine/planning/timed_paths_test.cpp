#include "engine/planning/timed_paths.h"

#include <gtest/gtest.h>

#include "grid_instances.h"

namespace dispatch::engine {
namespace {

using testing_grid::Grid;

// 0 1 2 3 in a row.
const std::vector<std::string> kRow = {"...."};

TEST(TimedPathsTest, AnAgentCostsTheStepItLastArrivesAtItsGoal) {
  EXPECT_EQ(PathCost({0}), 0);
  EXPECT_EQ(PathCost({0, 1, 2}), 2);
  EXPECT_EQ(PathCost({0, 1, 1, 1}), 1);      // trailing waits at the goal are free
  EXPECT_EQ(PathCost({0, 1, 0, 1, 1}), 3);   // it left its goal and came back at step 3
  EXPECT_EQ(SumOfCosts({{0, 1, 2}, {3, 3, 2, 1}}), 5);
}

TEST(TimedPathsTest, TwoAgentsAtOneVertexAtOneStepConflict) {
  const auto c = FirstConflict({{0, 1, 2}, {2, 1, 0}}, 4);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->kind, PathConflict::Kind::kVertex);
  EXPECT_EQ(c->a, 0);
  EXPECT_EQ(c->b, 1);
  EXPECT_EQ(c->time, 1);
  EXPECT_EQ(c->at, 1);
}

TEST(TimedPathsTest, TwoAgentsSwappingAlongOneEdgeConflict) {
  const auto c = FirstConflict({{0, 1, 2}, {3, 2, 1}}, 4);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->kind, PathConflict::Kind::kSwap);
  EXPECT_EQ(c->time, 2);
  EXPECT_EQ(c->at, 2);    // agent 0 arrives at 2 ...
  EXPECT_EQ(c->from, 1);  // ... from 1, while agent 1 goes 2 -> 1
}

TEST(TimedPathsTest, AnAgentStaysAtItsGoalAfterItsPathEnds) {
  // Agent 0 arrived at 1 at step 1 and stays; agent 1 passes through 1 at step 3.
  const auto c = FirstConflict({{0, 1}, {3, 3, 2, 1, 0}}, 4);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->kind, PathConflict::Kind::kVertex);
  EXPECT_EQ(c->time, 3);
  EXPECT_EQ(c->at, 1);
}

TEST(TimedPathsTest, FollowingOneStepBehindIsNoConflict) {
  EXPECT_FALSE(FirstConflict({{1, 2, 3}, {0, 1, 2}}, 4));
  EXPECT_EQ(CountConflicts({{1, 2, 3}, {0, 1, 2}}, 4), 0);
  EXPECT_EQ(CountConflicts({{0, 1, 2}, {2, 1, 0}, {3, 3, 3}}, 4), 1);
}

TEST(TimedPathsTest, TheCheckerNamesTheFirstFault) {
  const MapfGraph g = Grid(kRow);
  const std::vector<MapfAgent> agents = {{0, 1}, {3, 2}};
  auto fault = [&](const std::vector<TimedPath>& paths) { return CheckPaths(g, agents, paths).error().message; };
  EXPECT_TRUE(CheckPaths(g, agents, {{0, 1}, {3, 2}}).ok());
  EXPECT_NE(fault({{0, 1}, {3, 1, 2}}).find("agent 1 jumps from 3 to 1 at step 1"), std::string::npos);
  EXPECT_NE(fault({{1}, {3, 2}}).find("agent 0 does not start"), std::string::npos);
  EXPECT_NE(fault({{0}, {3, 2}}).find("agent 0 does not end"), std::string::npos);
  EXPECT_NE(fault({{0, 1}, {3, 2, 1, 2}}).find("both at vertex 1 at step 2"), std::string::npos);
  EXPECT_NE(fault({{0, 1}}).find("1 paths for 2 agents"), std::string::npos);
  EXPECT_NE(CheckPaths(g, {{0, 1}, {1, 0}}, {{0, 1}, {1, 0}}).error().message.find("swap"), std::string::npos);
}

TEST(TimedPathsTest, AnInstanceNeedsDistinctStartsAndGoalsOnTheGraph) {
  const MapfGraph g = Grid(kRow);
  EXPECT_TRUE(CheckAgents(g, {{0, 3}, {3, 0}}).ok());
  EXPECT_FALSE(CheckAgents(g, {{0, 3}, {0, 2}}).ok());
  EXPECT_FALSE(CheckAgents(g, {{0, 3}, {1, 3}}).ok());
  EXPECT_FALSE(CheckAgents(g, {{0, 4}}).ok());
  EXPECT_FALSE(CheckAgents(g, {{-1, 2}}).ok());
}

TEST(MapfGraphTest, StepsToAGoalFollowTheEdgesBackwards) {
  const std::vector<std::string> rows = {"...", ".@.", "..."};
  const MapfGraph g = Grid(rows);
  const auto steps = g.StepsTo(testing_grid::Cell(rows, 2, 2));
  EXPECT_EQ(steps[0], 4);
  EXPECT_EQ(steps[4], MapfGraph::kUnreachable);  // the blocked cell
  EXPECT_TRUE(g.Adjacent(0, 1));
  EXPECT_FALSE(g.Adjacent(1, 4));
  // A one-way edge is followed one way only.
  const MapfGraph one_way = MapfGraph::FromAdjacency({{1}, {}}).value();
  EXPECT_EQ(one_way.StepsTo(1)[0], 1);
  EXPECT_EQ(one_way.StepsTo(0)[1], MapfGraph::kUnreachable);
  EXPECT_FALSE(MapfGraph::FromAdjacency({{2}, {}}).ok());
}

// On a one-way loop with a spur the strongly connected part leaves out what cannot come back.
TEST(MapfGraphTest, APartHoldsWhatReachesAndIsReachedBack) {
  // 0 -> 1 -> 2 -> 0, 2 -> 3 (a dead end), 4 -> 0 (no way in).
  const MapfGraph g = MapfGraph::FromAdjacency({{1}, {2}, {0, 3}, {}, {0}}).value();
  EXPECT_EQ(g.StepsFrom(0), (std::vector<int>{0, 1, 2, 3, MapfGraph::kUnreachable}));
  EXPECT_EQ(g.PartOf(1), (std::vector<PointId>{0, 1, 2}));
  EXPECT_EQ(g.PartOf(3), (std::vector<PointId>{3}));
  const auto agents = RandomAgents(g.PartOf(0), 3, 5);
  ASSERT_TRUE(agents.ok());
  EXPECT_TRUE(CheckAgents(g, agents.value()).ok());
  for (const MapfAgent& a : agents.value()) EXPECT_NE(g.StepsTo(a.goal)[static_cast<std::size_t>(a.start)], MapfGraph::kUnreachable);
  EXPECT_EQ(RandomAgents(g.PartOf(0), 3, 5).value().front().start, agents.value().front().start);  // seeded
  EXPECT_FALSE(RandomAgents(g.PartOf(0), 4, 5).ok());
}

}  // namespace
}  // namespace dispatch::engine
