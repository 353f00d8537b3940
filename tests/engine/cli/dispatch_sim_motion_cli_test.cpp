// dispatch-sim motion: 4WIS hybrid A* vs. the baseline on the narrow floor, table and SVG.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "run_command.h"

namespace {

dispatch::testing::CommandRun Sim(const std::string& args) {
  return dispatch::testing::RunCommand(std::string(DISPATCH_SIM_BIN) + " motion " + args);
}

// The table row of `query` and `planner`, or "" when there is none.
std::string Row(const std::string& output, const std::string& query, const std::string& planner) {
  std::istringstream in(output);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string q, p;
    if (words >> q >> p && q == query && p == planner) return line;
  }
  return "";
}

std::string SolvedColumn(const std::string& row) {
  std::istringstream words(row);
  std::string q, p, solved;
  words >> q >> p >> solved;
  return solved;
}

TEST(DispatchSimMotionCliTest, TableHasBothPlannersPerQueryAndTheCrabSlotSplitsThem) {
  const std::string svg = MOTION_SVG_OUT;
  std::remove(svg.c_str());
  const auto run = Sim("--svg " + svg);
  ASSERT_EQ(run.status, 0) << run.output;
  for (const char* query : {"crab-slot", "dead-end", "cross-floor"}) {
    for (const char* planner : {"4wis", "baseline"}) {
      EXPECT_NE(Row(run.output, query, planner), "") << query << " " << planner << "\n" << run.output;
    }
  }
  EXPECT_EQ(SolvedColumn(Row(run.output, "crab-slot", "4wis")), "yes") << run.output;
  EXPECT_EQ(Row(run.output, "crab-slot", "baseline").find("no: unreachable") != std::string::npos, true)
      << run.output;
  EXPECT_EQ(SolvedColumn(Row(run.output, "dead-end", "baseline")), "yes") << run.output;
  EXPECT_EQ(SolvedColumn(Row(run.output, "cross-floor", "4wis")), "yes") << run.output;

  std::ifstream in(svg);
  ASSERT_TRUE(in.good()) << svg;
  std::stringstream text;
  text << in.rdbuf();
  const std::string s = text.str();
  EXPECT_EQ(s.rfind("<svg", 0), 0u);
  EXPECT_NE(s.find("</svg>"), std::string::npos);
  EXPECT_NE(s.find("class=\"grid-cell\""), std::string::npos);
  EXPECT_NE(s.find("data-label=\"crab-slot 4wis\""), std::string::npos);
  EXPECT_NE(s.find("data-label=\"cross-floor baseline\""), std::string::npos);
  EXPECT_EQ(s.find("data-label=\"crab-slot baseline\""), std::string::npos);  // unsolved: not drawn
  EXPECT_NE(s.find("#1f77b4"), std::string::npos);
  EXPECT_NE(s.find("#d62728"), std::string::npos);
  // Five paths, each with a polyline and several footprints.
  std::size_t polylines = 0, footprints = 0;
  for (std::size_t at = s.find("class=\"path\""); at != std::string::npos; at = s.find("class=\"path\"", at + 1)) ++polylines;
  for (std::size_t at = s.find("class=\"footprint\""); at != std::string::npos;
       at = s.find("class=\"footprint\"", at + 1)) {
    ++footprints;
  }
  EXPECT_EQ(polylines, 5u);
  EXPECT_GT(footprints, 5u * 3u);
}

TEST(DispatchSimMotionCliTest, OneQueryFromTheCommandLine) {
  const auto run = Sim("--from 1.0,0.8,0 --to 6.0,3.2,1.5708");
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_EQ(SolvedColumn(Row(run.output, "from-to", "4wis")), "yes") << run.output;
  EXPECT_NE(Row(run.output, "from-to", "baseline"), "") << run.output;
  EXPECT_EQ(Row(run.output, "crab-slot", "4wis"), "") << run.output;
}

// --robots: BIT2024 step 7 for three robots between the floor's stations (seed 3 has
// conflicts to eliminate: detours and a wait).
TEST(DispatchSimMotionCliTest, RobotsRunStepSevenConflictFree) {
  const std::string svg = std::string(MOTION_SVG_OUT) + ".robots.svg";
  std::remove(svg.c_str());
  const auto run = Sim("--robots 3 --seed 3 --svg " + svg);
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("3 robots, seed 3"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("conflict-free (checked every 0.1 s): yes"), std::string::npos) << run.output;
  EXPECT_EQ(run.output.find("rounds 0,"), std::string::npos) << run.output;
  for (const char* robot : {"\n0 ", "\n1 ", "\n2 "}) EXPECT_NE(run.output.find(robot), std::string::npos) << run.output;
  std::ifstream in(svg);
  ASSERT_TRUE(in.good()) << svg;
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find("data-label=\"robot 2\""), std::string::npos);
  // Same seed, same answer (the table above the timing line).
  auto table = [](const std::string& out) { return out.substr(0, out.find("conflict-free")); };
  EXPECT_EQ(table(Sim("--robots 3 --seed 3").output), table(run.output));
}

TEST(DispatchSimMotionCliTest, BadArgumentsFailWithAReason) {
  const auto half = Sim("--from 1,0.8,0");
  EXPECT_EQ(half.status, 1) << half.output;
  EXPECT_NE(half.output.find("go together"), std::string::npos) << half.output;
  const auto garbled = Sim("--from 1,0.8 --to 2,0.8,0");
  EXPECT_EQ(garbled.status, 1) << garbled.output;
  EXPECT_NE(garbled.output.find("x,y,theta"), std::string::npos) << garbled.output;
  const auto wall = Sim("--from 0,0,0 --to 2,0.8,0");
  EXPECT_EQ(wall.status, 1) << wall.output;
  EXPECT_NE(wall.output.find("collides"), std::string::npos) << wall.output;
  const auto nowhere = Sim("--svg /nonexistent-dir/x.svg --from 1,0.8,0 --to 2,0.8,0");
  EXPECT_EQ(nowhere.status, 1) << nowhere.output;
  EXPECT_NE(nowhere.output.find("cannot write"), std::string::npos) << nowhere.output;
  EXPECT_NE(Sim("--budget-ms -5").status, 0);
  EXPECT_NE(Sim("--robots").status, 0);
  const auto crowd = Sim("--robots 7");
  EXPECT_EQ(crowd.status, 1) << crowd.output;
  EXPECT_NE(crowd.output.find("at most 6 robots"), std::string::npos) << crowd.output;
  EXPECT_EQ(Sim("--robots 2 --from 1,0.8,0 --to 2,0.8,0").status, 1);
}

}  // namespace
