// dispatch-sim: the offline simulators (SPEC §3.8, issue 4).
//   dispatch-sim plan --table ../shared/scenarios/chu2024-table1.csv --rules both --csv fig8.csv
//       allocate a task table with the auction on the Chu2024 floor (R1..R18), execute the
//       timed plans with the Chu2024 rules off and/or on (seed 000 Fig. 8, Tables 3-4).
//   dispatch-sim stream --map chu2024 --robots 18 (--orders FILE... [--repeat N] | --random 200 --seed 1
//       [--formations 0.2]) [--strategy auction|greedy|exact|psoga] [--zeta 100] [--batch-window S]
//       [--orders-csv out.csv] [--check-safety] [--journal run.db] [--max-queue N]
//       [--formation-max-queue N] [--one-formation-per-pick true|false] [--trace R1,R2 [--trace-from T] [--trace-to T]]
//       [--planner rules|time-windows|conflict-elimination] [--routing floyd|heat [--heat-period S]] [--turn-time S]
//       an order stream with release times (formation orders too) on the dispatch core (the
//       service's allocation rounds and traffic gate, robots following its messages); with
//       --planner time-windows single-robot awards are planned through the others' time
//       windows (Wang2019, window_awards.h).
//   dispatch-sim compare [--random 200 --seed 1 --robots 18 --map chu2024]
//       [--planners rules,time-windows,conflict-elimination] [--routings floyd,heat] [--strategy S] [--zeta Z]
//       auction zeta=100, auction zeta=0 and greedy on one random stream (issue 4 §4), or the
//       planners side by side (both: stream_command.h).
//   dispatch-sim mapf --map FILE.map --agents N [--planner conflict-elimination|cbs|both]
//       the discrete-time planners on a floor (mapf_command.h).
//   dispatch-sim motion [--from X,Y,THETA --to X,Y,THETA | --robots N [--seed S]] [--svg FILE]
//       4WIS hybrid A* vs. the baseline on the narrow floor, or BIT2024 step 7 (motion_command.h).
//   dispatch-sim headon
//       seed 004 §4.3: a head-on conflict resolved by waiting vs. re-planning.
//   dispatch-sim routing [--tasks 4,8,12,16,20] [--seeds 5] [--turn-time 1]
//       seed 004 §4.1-4.2: traditional vs. improved Dijkstra (routing_command.h).
//   dispatch-sim replay --db dispatch.db [--run N | --list] [--what-if [--strategy S] [--zeta Z]
//       [--robots N]]
//       a run dispatchd recorded, through a fresh dispatch core again (exit 0: it matched);
//       with --what-if its orders re-run on the motion model, side by side (journal_replay.h).
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <utility>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/allocation/auction_allocator.h"
#include "engine/cli/journal_replay.h"
#include "engine/cli/lorr_command.h"
#include "engine/cli/mapf_command.h"
#include "engine/cli/motion_command.h"
#include "engine/cli/routing_command.h"
#include "engine/cli/stream_command.h"
#include "engine/cli/scenario.h"
#include "engine/dispatch/strategy.h"
#include "engine/io/map_source.h"
#include "engine/routing/route_table.h"
#include "engine/sim/head_on_scenario.h"
#include "engine/sim/simulator.h"
#include "engine/traffic/safety_check.h"

namespace dispatch::engine {
namespace {

using cli_stream::Fail;

void Print(const char* label, const SimResult& r, const SafetyReport& safety) {
  std::printf("Rules %s:\n", label);
  std::printf("  %-6s %-14s %10s %10s  %s\n", "order", "robots", "planned", "completed", "");
  for (const OrderOutcome& o : r.orders) {
    std::string team;
    for (const auto& id : o.robots) team += (team.empty() ? "" : " ") + id;
    if (o.completed) {
      std::printf("  %-6s %-14s %10.2f %10.2f\n", o.order_id.c_str(), team.c_str(),
                  o.planned_time, o.completion_time);
    } else {
      std::printf("  %-6s %-14s %10.2f %10s  failed: %s\n", o.order_id.c_str(), team.c_str(),
                  o.planned_time, "-", o.failure.c_str());
    }
  }
  std::printf("  makespan %.2f s, distance %.1f m, waiting %.1f s, stops %d, grants %zu "
              "(intersections %zu)\n",
              r.makespan, r.total_distance, r.total_waiting_time, r.stops, r.grants_issued,
              r.intersection_grants);
  std::printf("  min pairwise robot distance %.3f m; safety violations %zu\n",
              r.overall_min_distance, safety.violations.size());
  for (std::size_t i = 0; i < safety.violations.size() && i < 5; ++i) {
    std::printf("    %s\n", safety.violations[i].Describe().c_str());
  }
}

struct PlanArgs {
  std::string table, rules = "both", csv;
  double zeta = 100.0;
  std::optional<double> drop_time;  // AllocationConfig::drop_time (unset: the order's t_w)
  SimConfig sim;
};

int RunPlan(const PlanArgs& args) {
  const std::string& table = args.table;
  const std::string& rules = args.rules;
  const std::string& csv = args.csv;
  const double zeta = args.zeta;
  const SimConfig& sim = args.sim;
  AllocationConfig config;
  auto loaded = LoadMapSource("chu2024");
  if (!loaded.ok()) return Fail(loaded.error().message);
  auto map = std::make_shared<const WarehouseMap>(std::move(loaded).value());
  auto orders = LoadTaskTableOrders(*map, table);
  if (!orders.ok()) return Fail(orders.error().message);
  auto robots = RobotsAtStations(*map);
  if (!robots.ok()) return Fail(robots.error().message);
  RouteTableOptions route_options;
  route_options.speed = config.speed;
  auto routes = MakeRouteTable(map, route_options);
  if (!routes.ok()) return Fail(routes.error().message);
  std::shared_ptr<const RouteTable> shared_routes = std::move(routes).value();
  config.zeta = zeta;
  config.drop_time = args.drop_time;
  auto state = FleetState::Create(map, shared_routes, *robots, config);
  if (!state.ok()) return Fail(state.error().message);
  AuctionAllocator auction;
  int failed = 0;
  for (const auto& a : AllocateAll(auction, *orders, state.value())) {
    if (!a.award.ok()) {
      std::printf("%s: not allocated: %s\n", a.order_id.c_str(), a.award.error().message.c_str());
      ++failed;
    }
  }
  std::printf("Table %s, auction zeta = %g, dt = %g s\n", table.c_str(), zeta, sim.time_step);

  std::vector<const SimResult*> series(2, nullptr);  // off, on
  std::vector<SimResult> results;
  results.reserve(2);
  for (bool on : {false, true}) {
    if ((rules == "on" && !on) || (rules == "off" && on)) continue;
    SimConfig c = sim;
    c.traffic.rules_enabled = on;
    auto r = Simulate(*state, c);
    if (!r.ok()) return Fail(r.error().message);
    const SafetyReport safety = CheckSafety(r->frames, *map, c.traffic);
    Print(on ? "on" : "off", *r, safety);
    failed += !r->all_completed();
    results.push_back(std::move(r).value());
    series[on ? 1 : 0] = &results.back();
  }
  if (!csv.empty()) {
    std::ofstream out(csv);
    if (!out) return Fail("cannot write " + csv);
    out << "t,min_distance_off,min_distance_on\n";
    std::size_t n = 0;
    for (const SimResult* s : series) n = s ? std::max(n, s->times.size()) : n;
    for (std::size_t i = 0; i < n; ++i) {
      out << static_cast<double>(i) * sim.time_step;
      for (const SimResult* s : series) {
        out << ',';
        if (s && i < s->min_distance.size() && std::isfinite(s->min_distance[i])) {
          out << s->min_distance[i];
        }
      }
      out << '\n';
    }
  }
  return failed == 0 ? 0 : 2;
}

int RunHeadOn() {
  std::printf("Seed 004 §4.3: head-on on a single lane, h2 (lower priority) meets h1\n");
  std::printf("%-10s %-14s %10s %10s %10s  %s\n", "h1 work", "policy", "h2 time", "wait est",
              "detour +", "decision");
  for (double work : {30.0, 5.0}) {
    auto c = RunHeadOnComparison(work);
    if (!c.ok()) return Fail(c.error().message);
    for (auto [name, run] : {std::pair{"wait only", &c->wait}, std::pair{"re-plan", &c->replan},
                             std::pair{"controller", &c->chosen}}) {
      std::printf("%-10.0f %-14s %9.1fs %9.1fs %9.1fs  %s\n", work, name, run->h2_time,
                  run->wait_estimate, run->replan_extra, run->replanned ? "re-plan" : "wait");
    }
  }
  std::printf("\nSeed 004 §3.3 case 1: h1 (released first) and h2 drive at a corridor from its two ends, h2 first\n");
  std::printf("%-22s %10s %10s %10s  %s\n", "corridor", "h1 time", "h2 time", "deadlocks", "gave way");
  auto one = RunCaseOneComparison();
  if (!one.ok()) return Fail(one.error().message);
  for (auto [name, run] : {std::pair{"first come", &one->first_come}, std::pair{"higher priority first", &one->priority}}) {
    std::printf("%-22s %9.1fs %9.1fs %10zu  %s%s\n", name, run->h1_time, run->h2_time, run->deadlocks,
                run->h1_met_head_on ? "h1 " : "", run->h2_met_head_on ? "h2" : "");
  }
  return 0;
}

int Main(int argc, char** argv) {
  CLI::App app{"Offline simulators: timed plans (Chu2024) and order streams"};
  app.require_subcommand(1);
  PlanArgs plan;
  auto* p = app.add_subcommand("plan", "Task table -> auction -> timed plans under the Chu2024 rules");
  p->add_option("--table", plan.table, "Task table CSV (seed format)")->required();
  p->add_option("--zeta", plan.zeta, "Traffic weight of the auction (eq. 5)")->capture_default_str();
  p->add_option("--rules", plan.rules, "Traffic rules: on, off or both")->capture_default_str()
      ->check(CLI::IsMember({"on", "off", "both"}));
  p->add_option("--csv", plan.csv, "Write t,min_distance_off,min_distance_on here");
  p->add_option("--drop-time", plan.drop_time,
                "Seconds worked at a drop (default: the order's t_w; 0: the seed's model, eq. 3)")
      ->check(CLI::NonNegativeNumber);
  p->add_option("--dt", plan.sim.time_step, "Time step, s")->capture_default_str()
      ->check(CLI::PositiveNumber);
  StreamArgs stream, compare;
  const StreamCommands streams = AddStreamCommands(app, stream, compare);
  auto* h = app.add_subcommand("headon", "Seed 004 §4.3: wait vs. re-plan on a head-on conflict");
  ReplayArgs replay;
  auto* r = app.add_subcommand("replay", "A run dispatchd recorded, through the dispatch core again; --what-if");
  r->add_option("--db", replay.db, "dispatchd's SQLite file")->required();
  r->add_option("--run", replay.run, "Run number (default: the newest; --list shows them)");
  r->add_flag("--list", replay.list, "List the recorded runs");
  r->add_flag("--what-if", replay.what_if, "Also re-run the orders on the motion model, as recorded and changed");
  r->add_option("--strategy", replay.strategy, "What-if strategy (default: the recorded one)")
      ->check(CLI::IsMember(AllocatorNames()));
  r->add_option("--zeta", replay.zeta, "What-if traffic weight (default: the recorded one)");
  r->add_option("--robots", replay.robots, "What-if fleet: the first N robots of the run (default: all)");
  r->add_option("--dt", replay.dt, "What-if time step, s")->capture_default_str()->check(CLI::PositiveNumber);
  r->add_option("--max-time", replay.max_time, "What-if simulated seconds before giving up")->capture_default_str();
  MapfArgs mapf;
  auto* m = AddMapfCommand(app, mapf);
  LorrArgs lorr, lorr_check;
  const LorrCommands lorr_commands = AddLorrCommands(app, lorr, lorr_check);
  MotionArgs motion;
  auto* mo = AddMotionCommand(app, motion);
  RoutingArgs routing;
  auto* rt = AddRoutingCommand(app, routing);
  CLI11_PARSE(app, argc, argv);
  if (*rt) return RunRouting(routing);
  if (*m) return RunMapf(mapf);
  if (*lorr_commands.run) return RunLorr(lorr);
  if (*lorr_commands.check) return RunLorrCheck(lorr_check);
  if (*mo) return RunMotion(motion);
  if (*r) return RunReplay(replay);
  if (*p) return RunPlan(plan);
  if (*streams.stream) return RunStream(stream);
  if (*streams.compare) return RunCompare(compare);
  if (*h) return RunHeadOn();
  return 1;
}

}  // namespace
}  // namespace dispatch::engine

int main(int argc, char** argv) { return dispatch::engine::Main(argc, argv); }
