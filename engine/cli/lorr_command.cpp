#include "engine/cli/lorr_command.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <numeric>
#include <sstream>

#include "engine/dispatch/strategy.h"
#include "engine/lifelong/lifelong_run.h"
#include "engine/lifelong/lorr_check.h"
#include "engine/lifelong/lorr_output.h"

namespace dispatch::engine {

LorrCommands AddLorrCommands(CLI::App& app, LorrArgs& run, LorrArgs& check) {
  LorrCommands commands;
  auto* l = app.add_subcommand("lorr", "A LoRR 2024 lifelong problem through the product's allocation and planning");
  l->add_option("--problem", run.problem, "The problem JSON (../shared/benchmarks/lorr2024/...)")->required();
  l->add_option("--steps", run.steps, "One-second steps to simulate")->capture_default_str()->check(CLI::NonNegativeNumber);
  l->add_option("--output", run.output, "Write the competition's output JSON here");
  l->add_option("--plan-ms", run.plan_ms, "Time limit per step, ms (0: none; over it, robots wait as in the competition)")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  l->add_option("--strategy", run.strategy, "Allocation strategy")->capture_default_str()->check(CLI::IsMember(AllocatorNames()));
  l->add_option("--seed", run.seed, "Seed of the planner's tie-breaks")->capture_default_str();
  l->add_option("--route-cache-mb", run.route_cache_mb, "The lazy route table's cache on large floors, MiB")
      ->capture_default_str()->check(CLI::PositiveNumber);
  l->add_option("--route-table", run.route_table,
                "floyd (dense; lazy above 4,096 cells), dijkstra, auto, lazy or hub_labels (any floor, bounded memory)")
      ->capture_default_str()->check(CLI::IsMember(RouteTableMethodNames()));
  l->add_flag("--reassign,!--no-reassign", run.reassign,
              "Tasks not opened yet go back to the pool and their robots bid again, in steps whose pool's work "
              "is within --reassign-max-work and the credit --reassign-work-per-step builds")
      ->capture_default_str();
  l->add_option("--reassign-max-work", run.reassign_max_work,
                "Reassign only a pool whose work, min(robots, tasks)^2 x max(robots, tasks), is at most this")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  l->add_option("--reassign-work-per-step", run.reassign_work_per_step,
                "Reassignment work each step adds to the credit a reassignment spends (pools within it reassign "
                "every step, larger ones every few steps)")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  commands.run = l;
  auto* c = app.add_subcommand("lorr-check", "Replay a LoRR output JSON against its problem and check every rule");
  c->add_option("--problem", check.problem, "The problem JSON")->required();
  c->add_option("--output", check.output, "The output JSON to check")->required();
  commands.check = c;
  return commands;
}

int RunLorr(const LorrArgs& a) {
  const auto load_begin = std::chrono::steady_clock::now();
  Result<LorrProblem> problem = LoadLorrProblem(a.problem);
  if (!problem) {
    std::fprintf(stderr, "dispatch-sim: %s\n", problem.error().message.c_str());
    return 1;
  }
  const double load_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - load_begin).count();
  LifelongOptions options;
  options.steps = a.steps;
  options.plan_ms = a.plan_ms;
  options.strategy = a.strategy;
  options.seed = a.seed;
  options.route_cache_bytes = a.route_cache_mb << 20;
  options.route_method = ParseRouteTableMethod(a.route_table).value();
  options.reassign = a.reassign;
  options.reassign_max_work = a.reassign_max_work;
  options.reassign_work_per_step = a.reassign_work_per_step;
  const auto run_begin = std::chrono::steady_clock::now();
  Result<LifelongRecord> record = RunLifelong(*problem, options);
  if (!record) {
    std::fprintf(stderr, "dispatch-sim: %s\n", record.error().message.c_str());
    return 1;
  }
  const double run_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - run_begin).count();
  const std::vector<double>& times = record->planner_seconds;
  const double mean_ms = times.empty() ? 0.0 : 1000.0 * std::accumulate(times.begin(), times.end(), 0.0) / static_cast<double>(times.size());
  const double max_ms = times.empty() ? 0.0 : 1000.0 * *std::max_element(times.begin(), times.end());
  std::printf("%s: %d robots, %d steps, strategy %s, planner turn-pibt (seed %llu), routes %s\n",
              problem->name.c_str(), record->team_size, record->steps, record->strategy.c_str(),
              static_cast<unsigned long long>(a.seed), record->routes.c_str());
  std::printf("tasks finished %d, makespan %d, planner errors %d, schedule errors %d, entry timeouts %d\n",
              record->tasks_finished, record->makespan, record->planner_errors, record->schedule_errors,
              record->entry_timeouts);
  std::printf("planning per step: mean %.2f ms, max %.2f ms; load %.2f s, run %.2f s\n", mean_ms, max_ms, load_s, run_s);
  std::printf("tasks not opened yet reassigned in %d of %d steps\n", record->reassign_steps, record->steps);
  if (!a.output.empty()) {
    std::ofstream out(a.output, std::ios::binary);
    out << LorrOutputJson(*record, problem->grid) << '\n';
    if (!out) {
      std::fprintf(stderr, "dispatch-sim: %s: cannot write the output\n", a.output.c_str());
      return 1;
    }
  }
  return record->planner_errors == 0 ? 0 : 2;
}

int RunLorrCheck(const LorrArgs& a) {
  Result<LorrProblem> problem = LoadLorrProblem(a.problem);
  if (!problem) {
    std::fprintf(stderr, "dispatch-sim: %s\n", problem.error().message.c_str());
    return 1;
  }
  std::ifstream in(a.output, std::ios::binary);
  if (!in) {
    std::fprintf(stderr, "dispatch-sim: %s: cannot open the output\n", a.output.c_str());
    return 1;
  }
  std::ostringstream text;
  text << in.rdbuf();
  Result<LorrCheckReport> report = CheckLorrOutput(*problem, text.str());
  if (!report) {
    std::fprintf(stderr, "dispatch-sim: %s: %s\n", a.output.c_str(), report.error().message.c_str());
    return 1;
  }
  for (const std::string& p : report->problems) std::printf("%s\n", p.c_str());
  std::printf("%s: %d steps, %d tasks finished, %s\n", a.output.c_str(), report->steps, report->tasks_finished,
              report->ok() ? "valid" : "INVALID");
  return report->ok() ? 0 : 2;
}

}  // namespace dispatch::engine
