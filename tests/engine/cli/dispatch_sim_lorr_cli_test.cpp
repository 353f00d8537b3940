// dispatch-sim lorr / lorr-check: the LoRR 2024 lifelong benchmark from the command line on the
// public random instance, the output replayed by the checker, and a tampered output refused.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "run_command.h"

namespace {

dispatch::testing::CommandRun Sim(const std::string& args) {
  return dispatch::testing::RunCommand(std::string(DISPATCH_SIM_BIN) + " " + args);
}

const std::string kRandom =
    std::string(DISPATCH_SHARED_DIR) + "/benchmarks/lorr2024/example_problems/random.domain/random_32_32_20_100.json";

TEST(DispatchSimLorrCliTest, ARunWritesTheCompetitionsOutputAndTheCheckerReplaysIt) {
  const std::string out = std::string(LORR_OUT_DIR) + "/lorr_random.json";
  const auto run = Sim("lorr --problem " + kRandom + " --steps 60 --output " + out);
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("random_32_32_20_100: 100 robots, 60 steps, strategy exact"), std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("planner errors 0"), std::string::npos) << run.output;
  const auto check = Sim("lorr-check --problem " + kRandom + " --output " + out);
  ASSERT_EQ(check.status, 0) << check.output;
  EXPECT_NE(check.output.find("60 steps"), std::string::npos) << check.output;
  EXPECT_NE(check.output.find("valid"), std::string::npos) << check.output;

  // The output claims one task more than its events show.
  std::ifstream in(out);
  std::stringstream text;
  text << in.rdbuf();
  std::string json = text.str();
  const std::string key = "\"numTaskFinished\": ";
  const std::size_t at = json.find(key);
  ASSERT_NE(at, std::string::npos);
  const std::size_t digits = at + key.size();
  const std::size_t end = json.find_first_not_of("0123456789", digits);
  json.replace(digits, end - digits, std::to_string(std::stoi(json.substr(digits, end - digits)) + 1));
  const std::string bad = std::string(LORR_OUT_DIR) + "/lorr_random_tampered.json";
  std::ofstream(bad) << json;
  const auto refused = Sim("lorr-check --problem " + kRandom + " --output " + bad);
  EXPECT_EQ(refused.status, 2) << refused.output;
  EXPECT_NE(refused.output.find("INVALID"), std::string::npos) << refused.output;
}

TEST(DispatchSimLorrCliTest, BadArgumentsFailWithAReason) {
  const auto missing = Sim("lorr --problem /nonexistent/problem.json --steps 5");
  EXPECT_EQ(missing.status, 1) << missing.output;
  EXPECT_NE(missing.output.find("cannot open LoRR problem file"), std::string::npos) << missing.output;
  EXPECT_NE(Sim("lorr --problem " + kRandom + " --strategy nearest").status, 0);
  EXPECT_NE(Sim("lorr-check --problem " + kRandom).status, 0);  // --output is required
}

}  // namespace
