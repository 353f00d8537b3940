// dispatch-sim compare --planners: one table of the planners on the same stream (issue 16 §3),
// with why orders failed, the stops, and the safety check's violations.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "run_command.h"

namespace {

dispatch::testing::CommandRun Compare(const std::string& args) {
  return dispatch::testing::RunCommand(std::string(DISPATCH_SIM_BIN) + " compare " + args);
}

// The whitespace-separated fields of the table row that starts with `name`.
std::vector<std::string> Row(const std::string& output, const std::string& name) {
  std::istringstream lines(output);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream fields(line);
    std::vector<std::string> out;
    for (std::string f; fields >> f;) out.push_back(f);
    if (!out.empty() && out.front() == name) return out;
  }
  return {};
}

TEST(DispatchSimCompareCliTest, PlannersSideBySideWithFailuresStopsAndViolations) {
  const auto run = Compare("--random 30 --seed 1 --planners rules,time-windows,conflict-elimination --check-safety");
  ASSERT_EQ(run.status, 0) << run.output;
  for (const char* column : {"completed", "failed b/w/o", "stops", "replans", "deadlocks", "min dist", "violations", "ms/order"}) {
    EXPECT_NE(run.output.find(column), std::string::npos) << column << "\n" << run.output;
  }
  for (const char* planner : {"rules", "time-windows", "conflict-elimination"}) {
    const std::vector<std::string> row = Row(run.output, planner);
    ASSERT_EQ(row.size(), 14u) << planner << "\n" << run.output;
    EXPECT_EQ(row[1], "30/30") << run.output;
    EXPECT_EQ(row[2], "0/0/0") << run.output;
    EXPECT_EQ(row[12], "0") << run.output;  // violations
    EXPECT_GT(std::stod(row[13]), 0.0) << run.output;  // the rounds' time per award
  }
}

TEST(DispatchSimCompareCliTest, OrdersLeftAtTheTimeLimitAreCountedAsWaiting) {
  // 60 s cannot serve 30 orders: the rest are still waiting; no safety check, no violations
  // column.
  const auto run = Compare("--random 30 --seed 1 --planners rules --max-time 60");
  EXPECT_EQ(run.status, 2) << run.output;
  const std::vector<std::string> row = Row(run.output, "rules");
  ASSERT_EQ(row.size(), 14u) << run.output;
  const std::string failed = row[2];
  const std::size_t a = failed.find('/'), b = failed.rfind('/');
  ASSERT_NE(a, b) << failed;
  EXPECT_GT(std::stoul(failed.substr(a + 1, b - a - 1)), 0u) << run.output;
  EXPECT_EQ(failed.substr(b + 1), "0") << run.output;  // none counted as "other"
  EXPECT_EQ(row[12], "-") << run.output;
}

// Without --planners a column per strategy, the batch strategies included; a batch window
// applies to every column, and a negative one is refused.
TEST(DispatchSimCompareCliTest, StrategiesSideBySideWithABatchWindow) {
  const auto run = Compare("--random 20 --seed 3 --interval 0.3 --batch-window 4");
  ASSERT_EQ(run.status, 0) << run.output;
  for (const char* strategy : {"greedy", "exact", "psoga"}) {
    const std::vector<std::string> row = Row(run.output, strategy);
    ASSERT_EQ(row.size(), 14u) << strategy << "\n" << run.output;
    EXPECT_EQ(row[1], "20/20") << run.output;
  }
  const auto bad = Compare("--random 5 --batch-window -1");
  EXPECT_NE(bad.status, 0) << bad.output;
  EXPECT_NE(bad.output.find("--batch-window"), std::string::npos) << bad.output;
}

// The order-stream model is gone: the option that chose it is refused.
TEST(DispatchSimCompareCliTest, ThereIsNoModelToChoose) {
  const auto run = Compare("--random 5 --model stream");
  EXPECT_NE(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("--model"), std::string::npos) << run.output;
}

}  // namespace
