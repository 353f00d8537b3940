// Runs the real dispatch-map binary and checks what a person would read.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/engine/cli/run_command.h"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace {

using ::testing::HasSubstr;

using CliRun = dispatch::testing::CommandRun;

CliRun RunMap(const std::string& args) {
  return dispatch::testing::RunCommand(std::string(DISPATCH_MAP_BIN) + " " + args);
}

TEST(DispatchMapCliTest, SummaryOfTheChu2024Floor) {
  const CliRun r = RunMap("summary --map chu2024");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("Map 'chu2024'"));
  EXPECT_THAT(r.output, HasSubstr("shelves: 30, parking stations: 18 (108 slots)"));
  EXPECT_THAT(r.output, HasSubstr("Zones: 6"));
}

TEST(DispatchMapCliTest, RoutesBetweenNamedPointsAndStations) {
  const CliRun r = RunMap("routes --map chu2024 --from P1 --to D-T3");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("Route table: floyd"));
  EXPECT_THAT(r.output, HasSubstr("park-P1 > J1 >"));
  EXPECT_THAT(r.output, HasSubstr("> D-T3"));
  const CliRun sample = RunMap("routes --map chu2024 --method lazy --samples 3");
  EXPECT_EQ(sample.status, 0) << sample.output;
  EXPECT_THAT(sample.output, HasSubstr("Route table: lazy"));
}

// The route's line: from, to, length and time (the via column may differ between routes of
// equal cost).
std::string RouteFigures(const std::string& output) {
  std::istringstream lines(output);
  std::string line, last;
  while (std::getline(lines, line)) {
    if (!line.empty()) last = line;
  }
  std::istringstream fields(last);
  std::string from, to, length, time;
  fields >> from >> to >> length >> time;
  return from + " " + to + " " + length + " " + time;
}

TEST(DispatchMapCliTest, HubLabelsGiveTheFloydRoutesCost) {
  const CliRun floyd = RunMap("routes --map chu2024 --from P1 --to D-T3 --turn-penalty 2");
  const CliRun labels = RunMap("routes --map chu2024 --from P1 --to D-T3 --turn-penalty 2 --method hub_labels");
  ASSERT_EQ(labels.status, 0) << labels.output;
  EXPECT_THAT(labels.output, HasSubstr("Route table: hub_labels"));
  EXPECT_THAT(labels.output, HasSubstr("MiB"));
  EXPECT_EQ(RouteFigures(labels.output), RouteFigures(floyd.output)) << floyd.output << labels.output;
  EXPECT_THAT(RouteFigures(labels.output), HasSubstr("park-P1 D-T3"));
}

TEST(DispatchMapCliTest, WritesAnSvg) {
  const auto path = std::filesystem::path(DISPATCH_BINARY_DIR) / "dispatch_map_cli_test.svg";
  const CliRun r = RunMap("svg --map chu2024 --out " + path.string());
  EXPECT_EQ(r.status, 0) << r.output;
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_THAT(text.str(), HasSubstr("<svg"));
  EXPECT_THAT(text.str(), HasSubstr("</svg>"));
}

TEST(DispatchMapCliTest, BadInputIsAClearErrorAndNonZeroExit) {
  CliRun r = RunMap("summary --map nowhere.json");
  EXPECT_NE(r.status, 0);
  EXPECT_THAT(r.output, HasSubstr("nowhere.json"));
  r = RunMap("routes --map chu2024 --from P1 --to NOPE");
  EXPECT_NE(r.status, 0);
  EXPECT_THAT(r.output, HasSubstr("unknown point or station 'NOPE'"));
  r = RunMap("routes --map chu2024 --speed -1");
  EXPECT_NE(r.status, 0);
}

}  // namespace
