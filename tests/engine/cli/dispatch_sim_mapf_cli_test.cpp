// dispatch-sim mapf: the discrete-time planners from the command line on a public floor.
#include <gtest/gtest.h>

#include <string>

#include "run_command.h"

namespace {

dispatch::testing::CommandRun Sim(const std::string& args) {
  return dispatch::testing::RunCommand(std::string(DISPATCH_SIM_BIN) + " mapf " + args);
}

const std::string kRandomMap =
    std::string(DISPATCH_SHARED_DIR) + "/benchmarks/lorr2024/example_problems/random.domain/maps/random-32-32-20.map";

TEST(DispatchSimMapfCliTest, BothPlannersSolveAndPassTheChecker) {
  const auto run = Sim("--map " + kRandomMap + " --agents 20 --seed 3 --budget-ms 20000");
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("20 agents on"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("conflict-elimination        yes"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("cbs                         yes"), std::string::npos) << run.output;
}

TEST(DispatchSimMapfCliTest, AnImpossibleBudgetOrFleetFailsWithAReason) {
  const auto slow = Sim("--map " + kRandomMap + " --agents 200 --planner cbs --budget-ms 1");
  EXPECT_EQ(slow.status, 2) << slow.output;
  EXPECT_NE(slow.output.find("stopped"), std::string::npos) << slow.output;
  const auto crowd = Sim("--agents 100000");
  EXPECT_EQ(crowd.status, 1) << crowd.output;
  EXPECT_NE(crowd.output.find("do not fit"), std::string::npos) << crowd.output;
  EXPECT_NE(Sim("--planner astar").status, 0);
}

}  // namespace
