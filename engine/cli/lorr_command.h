// dispatch-sim lorr / lorr-check: the League of Robot Runners 2024 lifelong benchmark (issue 19
// §2) through the product's allocation and planning (engine/lifelong), and the independent
// checker of its output.
//   dispatch-sim lorr --problem FILE.json --steps N [--output out.json] [--plan-ms 100]
//       [--strategy exact|auction|greedy|psoga] [--seed S] [--route-cache-mb 4096]
//       [--route-table floyd|...|hub_labels] [--no-reassign] [--reassign-max-work W]
//       [--reassign-work-per-step C]
//   dispatch-sim lorr-check --problem FILE.json --output out.json
// `lorr` prints tasks finished, makespan, errors and planning time per step (mean, max) and
// writes the competition's output JSON; exit 0, or 2 when the run had planner errors.
// `lorr-check` replays the output (lorr_check.h): exit 0 when it is valid, 2 with the problems.
#pragma once

#include <cstdint>
#include <string>

#include "engine/lifelong/lifelong_run.h"

namespace CLI {
class App;
}

namespace dispatch::engine {

struct LorrArgs {
  std::string problem;
  int steps = 500;
  std::string output;
  double plan_ms = 0.0;
  std::string strategy = "exact";
  std::uint64_t seed = 0;
  std::size_t route_cache_mb = 4096;
  std::string route_table = "floyd";  // RouteTableMethodNames()
  bool reassign = true;                // LifelongOptions::reassign
  double reassign_max_work = LifelongOptions{}.reassign_max_work;
  double reassign_work_per_step = LifelongOptions{}.reassign_work_per_step;
};

struct LorrCommands {
  CLI::App* run = nullptr;
  CLI::App* check = nullptr;
};

LorrCommands AddLorrCommands(CLI::App& app, LorrArgs& run, LorrArgs& check);
int RunLorr(const LorrArgs& args);
int RunLorrCheck(const LorrArgs& args);

}  // namespace dispatch::engine
