#include "engine/planning/cbs.h"

#include <gtest/gtest.h>

#include <random>

#include "grid_instances.h"

namespace dispatch::engine {
namespace {

using testing_grid::Cell;
using testing_grid::Grid;

TEST(CbsTest, TwoAgentsPassInACorridorThroughASiding) {
  // A corridor with one siding cell above its middle: the agents swap ends.
  const std::vector<std::string> rows = {"@@.@@", "....."};
  const MapfGraph g = Grid(rows);
  const std::vector<MapfAgent> agents = {{Cell(rows, 1, 0), Cell(rows, 1, 4)}, {Cell(rows, 1, 4), Cell(rows, 1, 0)}};
  const auto solved = SolveCbs(g, agents);
  ASSERT_TRUE(solved.ok()) << solved.error().message;
  EXPECT_TRUE(CheckPaths(g, agents, solved.value().paths).ok());
  EXPECT_EQ(solved.value().sum_of_costs, testing_grid::BruteForceSumOfCosts(g, agents).value());
  // One waits a step for the other to step aside, which then comes back: 5 + 6.
  EXPECT_EQ(solved.value().sum_of_costs, 11);
}

TEST(CbsTest, AJointlyImpossibleInstanceIsStoppedByItsLimits) {
  const std::vector<std::string> rows = {"...."};  // two agents swap ends of a corridor
  const MapfGraph g = Grid(rows);
  const std::vector<MapfAgent> agents = {{0, 3}, {3, 0}};
  ASSERT_FALSE(testing_grid::BruteForceSumOfCosts(g, agents));
  PlanLimits limits;
  limits.max_expansions = 200;
  const auto solved = SolveCbs(g, agents, limits);
  ASSERT_FALSE(solved.ok());
  EXPECT_EQ(solved.error().code, ErrorCode::kFailedPrecondition);
  EXPECT_NE(solved.error().message.find("stopped after 200 nodes"), std::string::npos);
}

TEST(CbsTest, BadInstancesAreRefused) {
  const MapfGraph g = Grid({".@."});
  EXPECT_EQ(SolveCbs(g, {{0, 2}}).error().code, ErrorCode::kUnreachable);
  EXPECT_EQ(SolveCbs(g, {{0, 2}, {0, 1}}).error().code, ErrorCode::kInvalidArgument);
  EXPECT_TRUE(SolveCbs(g, {}).ok());
}

// Model test: on random tiny grids, whatever CBS returns passes the checker and its sum of
// costs is the brute-force optimum; where brute force finds no solution CBS finds none
// either. Plain CBS can need exponentially many nodes where two agents must pass each other
// in a corridor (Li et al. 2020's corridor reasoning is not in it), so a few instances stop
// at the node limit; nearly all must be solved.
TEST(CbsTest, OnRandomTinyGridsCbsIsOptimal) {
  std::mt19937_64 random(20261204);
  int solvable = 0, solved = 0, impossible = 0;
  for (int round = 0; round < 150; ++round) {
    const int width = 3 + static_cast<int>(random() % 2), height = 3 + static_cast<int>(random() % 2);
    const int agents = 2 + static_cast<int>(random() % 2);
    const auto in = testing_grid::RandomInstance(random, width, height, 0.2, agents);
    if (in.agents.empty()) continue;
    const MapfGraph g = Grid(in.rows);
    const auto optimum = testing_grid::BruteForceSumOfCosts(g, in.agents);
    PlanLimits limits;
    limits.max_expansions = 20000;
    const auto cbs = SolveCbs(g, in.agents, limits);
    SCOPED_TRACE("round " + std::to_string(round));
    if (!optimum) {
      EXPECT_FALSE(cbs.ok());
      ++impossible;
      continue;
    }
    ++solvable;
    if (!cbs.ok()) {
      EXPECT_EQ(cbs.error().code, ErrorCode::kFailedPrecondition) << cbs.error().message;
      continue;
    }
    EXPECT_TRUE(CheckPaths(g, in.agents, cbs.value().paths).ok());
    EXPECT_EQ(cbs.value().sum_of_costs, *optimum);
    ++solved;
  }
  EXPECT_GE(solvable, 100);  // the instances are mostly solvable: the test compares something
  EXPECT_GE(solved * 100, solvable * 97);
  EXPECT_GE(impossible, 1);
  RecordProperty("solvable", solvable);
  RecordProperty("solved", solved);
}

}  // namespace
}  // namespace dispatch::engine
