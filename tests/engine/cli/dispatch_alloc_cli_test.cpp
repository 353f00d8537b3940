// Runs the real dispatch-alloc binary on the seed's Table 2 (Chu2024 Tables 3 and 4
// reproduction) and checks what the paper's tables show: every task allocated, formations
// with 3 distinct robots, and every printed bid equal to eq. (4) recomputed from its terms.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/engine/cli/run_command.h"

#include <regex>
#include <set>
#include <sstream>

namespace {

using ::testing::HasSubstr;

using CliRun = dispatch::testing::CommandRun;

CliRun RunAlloc(const std::string& args) {
  return dispatch::testing::RunCommand(std::string(DISPATCH_ALLOC_BIN) + " " + args);
}

const std::string kTable2 = std::string(DISPATCH_SHARED_DIR) + "/scenarios/chu2024-table2.csv";

TEST(DispatchAllocCliTest, Table2AllocatesEveryTaskInThePapersShape) {
  const CliRun r = RunAlloc("--table " + kTable2);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("Allocation, auction, zeta = 0"));
  EXPECT_THAT(r.output, HasSubstr("Allocation, auction, zeta = 100"));
  EXPECT_THAT(r.output, HasSubstr("Bids behind T8"));
  EXPECT_THAT(r.output, HasSubstr("Changed between zeta = 0 and zeta = 100"));
  // Task rows: "  T<k>  R.. [R.. R..]  <bid>  <why>".
  const std::regex row(R"(^  (T\d+)\s+((?:R\d+ ?)+)\s+(\d+\.\d+)\s+(leader )?R\d+)");
  const std::set<std::string> formations = {"T1", "T2", "T5", "T8"};  // Table 2's formation=1
  int rows = 0;
  std::istringstream lines(r.output);
  for (std::string line; std::getline(lines, line);) {
    std::smatch m;
    if (!std::regex_search(line, m, row)) continue;
    ++rows;
    std::istringstream team(m[2].str());
    std::set<std::string> robots;
    for (std::string robot; team >> robot;) robots.insert(robot);
    EXPECT_EQ(robots.size(), formations.count(m[1].str()) ? 3u : 1u) << line;
  }
  EXPECT_EQ(rows, 16);  // 8 tasks x 2 runs
  EXPECT_THAT(r.output, ::testing::Not(HasSubstr("error:")));
}

TEST(DispatchAllocCliTest, PrintedBidsEqualTheFormula) {
  const CliRun r = RunAlloc("--table " + kTable2 + " --zeta 0 --zeta 100");
  ASSERT_EQ(r.status, 0) << r.output;
  const std::regex bid(
      R"(B=\s*([\d.]+)\s+T_t=\s*([\d.]+)\s+T_d=\s*([\d.]+)\s+T_w=\s*([\d.]+)\s+F=([\d.]+)\s+x=\s*([\d.]+))");
  int checked = 0;
  std::istringstream lines(r.output);
  double zeta = -1;
  for (std::string line; std::getline(lines, line);) {
    if (line.find("zeta = 0:") != std::string::npos) zeta = 0;
    if (line.find("zeta = 100:") != std::string::npos) zeta = 100;
    std::smatch m;
    if (!std::regex_search(line, m, bid)) continue;
    const double b = std::stod(m[1]), t_t = std::stod(m[2]), t_d = std::stod(m[3]),
                 t_w = std::stod(m[4]), f = std::stod(m[5]), x = std::stod(m[6]);
    EXPECT_NEAR(t_t, t_d + t_w, 0.011) << line;                 // eq. (2)
    EXPECT_NEAR(x, zeta * f, 0.006 + zeta * 0.00005) << line;   // eq. (5), F printed to 1e-4
    EXPECT_NEAR(b, 0.5 * t_t + 0.5 * t_d + x, 0.011) << line;   // eq. (4)
    ++checked;
  }
  EXPECT_EQ(checked, 6);  // T8's leader and 2 companions, for each zeta
}

TEST(DispatchAllocCliTest, GreedyBaselineAndBadInput) {
  CliRun r = RunAlloc("--table " + kTable2 + " --strategy greedy --zeta 0");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("Allocation, greedy, zeta = 0"));
  r = RunAlloc("--table /nonexistent.csv");
  EXPECT_NE(r.status, 0);
  EXPECT_THAT(r.output, HasSubstr("cannot read task table '/nonexistent.csv'"));
  r = RunAlloc("--table " + kTable2 + " --robots 2");
  EXPECT_NE(r.status, 0);  // formations need 3 robots: those tasks fail, the others allocate
  EXPECT_THAT(r.output, HasSubstr("error:"));
  EXPECT_THAT(r.output, ::testing::ContainsRegex("T3 +R[12] "));
}

}  // namespace
