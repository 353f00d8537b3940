#include "engine/cli/stream_command.h"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <tuple>
#include <utility>

#include "engine/cli/journal_replay.h"
#include "engine/cli/scenario.h"
#include "engine/dispatch/strategy.h"
#include "engine/io/map_source.h"
#include "engine/routing/route_table.h"
#include "engine/sim/core_stream.h"
#include "engine/sim/fleet_placement.h"
#include "engine/sim/random_orders.h"

namespace dispatch::engine {

namespace cli_stream {
int Fail(const std::string& message) {
  std::cerr << "dispatch-sim: " << message << "\n";
  return 1;
}
}  // namespace cli_stream

namespace {

using cli_stream::Fail;

// "rules, time-windows, conflict-elimination" for messages and help texts.
std::string PlannerList() {
  std::string out;
  for (const std::string& name : PlannerNames()) out += (out.empty() ? "" : ", ") + name;
  return out;
}


struct Setup {
  std::shared_ptr<const WarehouseMap> map;
  std::shared_ptr<const RouteTable> routes;
  std::vector<FleetRobot> robots;
  std::vector<Order> orders;
};

Result<Setup> Prepare(const StreamArgs& a) {
  Setup s;
  auto loaded = LoadMapSource(a.map);
  if (!loaded.ok()) return loaded.error();
  s.map = std::make_shared<const WarehouseMap>(std::move(loaded).value());
  RouteTableOptions route_options;
  route_options.turn_penalty_s = a.turn_s;  // T_d counts turning as the plans do
  auto method = ParseRouteTableMethod(a.route_table);
  if (!method.ok()) return method.error();
  route_options.method = *method;
  auto routes = MakeRouteTable(s.map, route_options);
  if (!routes.ok()) return routes.error();
  s.routes = std::move(routes).value();
  auto robots = PlaceRobots(*s.map, a.robots);
  if (!robots.ok()) return robots.error();
  s.robots = std::move(robots).value();
  if (!a.orders.empty()) {
    // Every table `repeat` times, all at once: with two tables, copy k of table 2's task T3
    // is T3.2-k.
    std::vector<std::vector<Order>> tables;
    for (const std::string& path : a.orders) {
      auto loaded = LoadTaskTableOrders(*s.map, path);
      if (!loaded.ok()) return loaded.error();
      tables.push_back(std::move(loaded).value());
    }
    for (std::size_t k = 1; k <= a.repeat; ++k) {
      for (std::size_t i = 0; i < tables.size(); ++i) {
        for (Order o : tables[i]) {
          if (tables.size() > 1) o.id += "." + std::to_string(i + 1);
          if (a.repeat > 1) o.id += "-" + std::to_string(k);
          o.client_id = o.id;
          s.orders.push_back(std::move(o));
        }
      }
    }
  } else {
    RandomOrderOptions ro;
    ro.count = a.random;
    ro.seed = a.seed;
    ro.interval = a.interval;
    ro.formation_share = a.formations;
    auto orders = RandomOrders(*s.map, ro);
    if (!orders.ok()) return orders.error();
    s.orders = std::move(orders).value();
  }
  return s;
}

StreamConfig ConfigOf(const StreamArgs& a, const std::string& strategy, double zeta) {
  StreamConfig c;
  c.time_step = a.dt;
  c.max_time = a.max_time;
  c.allocation_period = a.batch_window;
  c.strategy = ParseAllocationStrategy(strategy).value_or(AllocationStrategy::kAuction);  // checked by CLI11
  c.allocation.zeta = zeta;
  c.allocation.max_queue = a.max_queue;
  c.allocation.formation_max_queue = a.formation_max_queue;
  c.allocation.planner = ParsePlanner(a.planner).value_or(PlannerKind::kRules);
  c.allocation.turn_time = a.turn_s;
  c.allocation.drop_time = a.drop_s;
  c.allocation.routing = ParseRouting(a.routing).value_or(RoutingKind::kFloyd);
  c.allocation.heat_period = a.heat_period;
  c.traffic.priority_by_release = a.priority == "release";
  c.traffic.head_on_priority = a.head_on_priority;
  c.traffic.head_on_give_way = a.head_on_give_way;
  c.traffic.execution = ParsePlanExecution(a.execution).value_or(DefaultPlanExecution(c.allocation.planner));
  c.one_formation_per_pick = a.one_formation_per_pick;
  c.blocked_recovery = a.blocked_recovery;
  c.check_safety = a.check_safety;
  c.trace_robots = a.trace;
  c.trace_from = a.trace_from;
  c.trace_to = a.trace_to;
  return c;
}

// "t1.csv + t2.csv x 10"
std::string TablesLabel(const StreamArgs& a) {
  std::string out;
  for (const std::string& t : a.orders) out += (out.empty() ? "" : " + ") + t;
  if (a.repeat > 1) out += " x " + std::to_string(a.repeat);
  return out;
}

Result<StreamResult> Simulate(const StreamArgs& a, const Setup& s, const StreamConfig& c) {
  if (!ParsePlanner(a.planner)) return InvalidArgument("--planner must be one of " + PlannerList());
  if (!ParseRouting(a.routing)) return InvalidArgument("--routing must be floyd or heat");
  if (a.journal.empty()) return SimulateOnCore(s.map, s.routes, s.robots, s.orders, c);
  std::vector<JournalEntry> journal;
  auto r = SimulateOnCore(s.map, s.routes, s.robots, s.orders, c, &journal);
  if (!r.ok()) return r;
  if (auto written = WriteSimulationJournal(a.journal, a.map, *s.map, c, journal); !written.ok()) {
    return written.error();
  }
  return r;
}

void PrintSummary(const std::string& label, const StreamResult& r) {
  std::printf("%s: %zu/%zu orders completed, makespan %.1f s, throughput %.1f orders/h, "
              "mean completion %.1f s\n",
              label.c_str(), r.completed, r.orders.size(), r.makespan, r.throughput_per_hour,
              r.mean_completion);
  std::printf("  distance %.1f m, waiting %.1f s, stops %zu, re-plans %zu, grants %zu, "
              "deadlocks resolved %zu, nudges %zu, head-on %zu, give-ways %zu, min distance %.3f m\n",
              r.total_distance, r.total_waiting_time, r.stops, r.traffic.replans,
              r.traffic.grants, r.traffic.deadlocks_resolved, r.traffic.nudges,
              r.traffic.head_on_conflicts, r.traffic.give_ways, r.overall_min_distance);
  if (!r.min_pair.empty()) std::printf("  closest: %s at %.1f s\n", r.min_pair.c_str(), r.min_time);
  if (r.safety) {
    std::printf("  safety check: %zu violations\n", r.safety->violations.size());
    for (std::size_t i = 0; i < r.safety->violations.size() && i < 5; ++i) {
      std::printf("    %s\n", r.safety->violations[i].Describe().c_str());
    }
  }
  for (const std::string& line : r.trace) std::printf("  trace: %s\n", line.c_str());
  for (std::size_t i = 0; i < r.too_close.size() && i < 5; ++i) {
    std::printf("  too close: %s\n", r.too_close[i].c_str());
  }
  for (std::size_t i = 0; i < r.blocked.size() && i < 5; ++i) {
    std::printf("  blocked: %s\n", r.blocked[i].c_str());
  }
  if (!r.recovered.empty()) {
    std::printf("  back in service after a block: %zu (first %s)\n", r.recovered.size(), r.recovered.front().c_str());
  }
  std::size_t shown = 0;
  for (const StreamOrderOutcome& o : r.orders) {
    if (o.completed || shown++ >= 5) continue;
    std::printf("  %s failed: %s\n", o.order_id.c_str(), o.failure.c_str());
  }
}

}  // namespace

int RunStream(const StreamArgs& a) {
  if (a.orders.empty() && a.random == 0) return Fail("stream: give --orders FILE or --random N");
  auto setup = Prepare(a);
  if (!setup.ok()) return Fail(setup.error().message);
  auto r = Simulate(a, *setup, ConfigOf(a, a.strategy, a.zeta));
  if (!r.ok()) return Fail(r.error().message);
  char label[1024];
  std::snprintf(label, sizeof label, "%s on %s, %zu robots, %s (zeta %g)",
                a.orders.empty() ? "random stream" : TablesLabel(a).c_str(), a.map.c_str(),
                setup->robots.size(), a.strategy.c_str(), a.zeta);
  PrintSummary(label, *r);
  if (!a.orders_csv.empty()) {
    std::ofstream out(a.orders_csv);
    if (!out) return Fail("cannot write " + a.orders_csv);
    out << "order,robot,release,completion,completed,failure,team\n";
    for (const StreamOrderOutcome& o : r->orders) {
      std::string team;  // a formation's members, leader first
      for (const std::string& id : o.team) team += (team.empty() ? "" : " ") + id;
      out << o.order_id << ',' << o.robot << ',' << o.release_time << ',';
      if (o.completed) out << o.completion_time;
      out << ',' << (o.completed ? 1 : 0) << ",\"" << o.failure << "\"," << team << '\n';
    }
  }
  return r->all_completed() && (!r->safety || r->safety->ok()) ? 0 : 2;
}

namespace {

// An order that did not complete, by why: blocked (the controller or a team's rendezvous gave
// up on it), still waiting at the time limit, or anything else (unreachable, cancelled).
struct FailureCounts {
  std::size_t blocked = 0, waiting = 0, other = 0;
};
FailureCounts CountFailures(const StreamResult& r) {
  FailureCounts n;
  for (const StreamOrderOutcome& o : r.orders) {
    if (o.completed) continue;
    if (o.open_at_limit) {
      ++n.waiting;
    } else if (o.failure.find("blocked") != std::string::npos) {
      ++n.blocked;
    } else {
      ++n.other;
    }
  }
  return n;
}

}  // namespace

int RunCompare(StreamArgs a) {
  if (a.orders.empty() && a.random == 0) a.random = 200;
  auto setup = Prepare(a);
  if (!setup.ok()) return Fail(setup.error().message);
  std::printf("%zu orders (%s), %zu robots on %s, dt %g s\n", setup->orders.size(),
              a.orders.empty() ? ("random, seed " + std::to_string(a.seed)).c_str()
                               : TablesLabel(a).c_str(),
              setup->robots.size(), a.map.c_str(), a.dt);
  // failed: blocked / still waiting at --max-time / other; violations: with --check-safety.
  // ms/order: wall time of the allocation rounds (auction and planner) per award.
  std::printf("%-20s %9s %11s %10s %12s %10s %10s %6s %9s %8s %9s %8s %10s %9s\n",
              a.planners.empty() && a.routings.empty() ? "strategy" : "planner", "completed", "failed b/w/o",
              "makespan", "throughput/h", "mean compl", "waiting s", "stops", "distance", "replans", "deadlocks",
              "min dist", "violations", "ms/order");
  int rc = 0;
  // name, strategy, zeta, planner, routing
  std::vector<std::tuple<std::string, std::string, double, std::string, std::string>> columns;
  if (a.planners.empty() && a.routings.empty()) {
    columns = {{"auction zeta=100", "auction", 100.0, a.planner, a.routing},
               {"auction zeta=0", "auction", 0.0, a.planner, a.routing},
               {"greedy", "greedy", 0.0, a.planner, a.routing},
               {"exact", "exact", 100.0, a.planner, a.routing},
               {"psoga", "psoga", 100.0, a.planner, a.routing}};
  } else {
    const std::vector<std::string> planners = a.planners.empty() ? std::vector<std::string>{a.planner} : a.planners;
    const std::vector<std::string> routings = a.routings.empty() ? std::vector<std::string>{a.routing} : a.routings;
    for (const std::string& p : planners) {
      for (const std::string& r : routings) {
        columns.emplace_back(routings.size() > 1 ? p + "/" + r : p, a.strategy, a.zeta, p, r);
      }
    }
  }
  for (const auto& [name, strategy, zeta, planner, routing] : columns) {
    StreamArgs with = a;
    with.planner = planner;
    with.routing = routing;
    StreamConfig c = ConfigOf(with, strategy, zeta);
    auto r = Simulate(with, *setup, c);
    if (!r.ok()) return Fail(r.error().message);
    const FailureCounts failed = CountFailures(*r);
    char failures[48];
    std::snprintf(failures, sizeof failures, "%zu/%zu/%zu", failed.blocked, failed.waiting, failed.other);
    const std::string violations = r->safety ? std::to_string(r->safety->violations.size()) : "-";
    const double per_order =
        r->planned_awards > 0 ? 1000.0 * r->planning_seconds / static_cast<double>(r->planned_awards) : 0.0;
    std::printf("%-20s %5zu/%-3zu %11s %10.1f %12.1f %10.1f %10.1f %6zu %9.1f %8zu %9zu %8.3f %10s %9.3f\n",
                name.c_str(), r->completed, r->orders.size(), failures, r->makespan, r->throughput_per_hour,
                r->mean_completion, r->total_waiting_time, r->stops, r->total_distance, r->traffic.replans,
                r->traffic.deadlocks_resolved, r->overall_min_distance, violations.c_str(), per_order);
    if (!r->all_completed() || (r->safety && !r->safety->ok())) rc = 2;
  }
  return rc;
}

StreamCommands AddStreamCommands(CLI::App& app, StreamArgs& stream_args, StreamArgs& compare_args) {
  auto add_stream = [](CLI::App* c, StreamArgs& a) {
    c->add_option("--map", a.map, "chu2024, a JSON map file or a MovingAI .map")->capture_default_str();
    c->add_option("--robots", a.robots, "Robots (stations first, then lane points)")->capture_default_str();
    c->add_option("--orders", a.orders, "Task table CSVs (optional release column), submitted together");
    c->add_option("--repeat", a.repeat, "Submit the task tables this many times at once")
        ->capture_default_str()->check(CLI::PositiveNumber);
    c->add_option("--random", a.random, "Random orders instead of a table");
    c->add_option("--seed", a.seed, "Seed of the random orders")->capture_default_str();
    c->add_option("--interval", a.interval, "Mean seconds between random releases")->capture_default_str();
    c->add_option("--formations", a.formations, "Share of random orders that are formation orders")
        ->capture_default_str()->check(CLI::Range(0.0, 1.0));
    c->add_option("--dt", a.dt, "Time step, s")->capture_default_str()->check(CLI::PositiveNumber);
    c->add_option("--max-time", a.max_time, "Simulated seconds before giving up")->capture_default_str();
    c->add_option("--batch-window", a.batch_window,
                  "Seconds between allocation rounds at least (0: a round as soon as one is due)")
        ->capture_default_str()->check(CLI::NonNegativeNumber);
    c->add_option("--planner", a.planner, "How awards get their routes: " + PlannerList())
        ->capture_default_str();
    c->add_option("--turn-time", a.turn_s, "Turning time per 90 degrees, s (plans, route costs, robots)")
        ->capture_default_str()->check(CLI::NonNegativeNumber);
    c->add_option("--drop-time", a.drop_s,
                  "Seconds a robot works at a drop (default: the order's t_w; 0: the seed's model, "
                  "Chu2024 eq. 3 counts the picks only)")
        ->check(CLI::NonNegativeNumber);
    c->add_option("--routing", a.routing, "Routes of the rules planner: floyd (shortest) or heat (Wang2019)")
        ->capture_default_str();
    c->add_option("--route-table", a.route_table,
                  "The shortest-route table: floyd (dense; lazy above 4,096 points), dijkstra, auto, lazy or "
                  "hub_labels (any floor, bounded memory)")
        ->capture_default_str()->check(CLI::IsMember(RouteTableMethodNames()));
    c->add_option("--priority", a.priority, "Traffic priority within a class: index or release (Wang2019)")
        ->capture_default_str()->check(CLI::IsMember({"index", "release"}));
    c->add_option("--head-on-priority", a.head_on_priority,
                  "Wang2019 case 1: give way at a free corridor to a higher-priority robot about to enter it (true|false)")
        ->capture_default_str();
    c->add_option("--head-on-give-way", a.head_on_give_way,
                  "Wang2019 case 2: a waiting robot met head-on by a higher-priority one drives off its way (true|false)")
        ->capture_default_str();
    c->add_option("--execution", a.execution,
                  "When a robot asks for its next point: times (at its planned departure), claim (once its work "
                  "is done) or order (claim, each point passed in the plans' order, Wang2019 3.2); default: times "
                  "with the rules planner, claim with the others")
        ->check(CLI::IsMember({"times", "claim", "order"}));
    c->add_option("--heat-period", a.heat_period, "Path heat: the period δ the lanes' use is counted over, s")
        ->capture_default_str()->check(CLI::PositiveNumber);
    c->add_option("--max-queue", a.max_queue, "Orders a robot may hold and still bid (0: no limit)")
        ->capture_default_str();
    c->add_option("--formation-max-queue", a.formation_max_queue,
                  "Orders a robot may hold and still join a formation (0: no limit)")
        ->capture_default_str();
    c->add_option("--one-formation-per-pick", a.one_formation_per_pick,
                  "Allocate a formation only while no other is heading for its first pick: true or false")
        ->capture_default_str();
    c->add_option("--blocked-recovery", a.blocked_recovery,
                  "s a blocked robot stays in fault before it is back in service (0: never)")
        ->capture_default_str()
        ->check(CLI::NonNegativeNumber);
    c->add_flag("--check-safety", a.check_safety,
                "Run CheckSafety over every step (eps1 spacing, crossings in intersections)");
    c->add_option("--trace", a.trace,
                  "Robots to trace every step: true position, motion, the gate's view")
        ->delimiter(',');
    c->add_option("--trace-from", a.trace_from, "Start of the trace window, s")->capture_default_str();
    c->add_option("--trace-to", a.trace_to, "End of the trace window, s");
  };
  CLI::App* s = app.add_subcommand("stream", "Order stream under the online traffic controller");
  add_stream(s, stream_args);
  s->add_option("--strategy", stream_args.strategy, "auction, greedy, exact or psoga")->capture_default_str()
      ->check(CLI::IsMember(AllocatorNames()));
  s->add_option("--zeta", stream_args.zeta, "Traffic weight of the auction")->capture_default_str();
  s->add_option("--orders-csv", stream_args.orders_csv, "Write per-order results here");
  s->add_option("--journal", stream_args.journal,
                "Journal the core's calls as a run of this SQLite file (dispatch-sim replay --db, SQL)");
  CLI::App* c = app.add_subcommand("compare", "Auction zeta=100 / zeta=0 / greedy / PSO-GA on one stream, or planners");
  add_stream(c, compare_args);
  c->add_option("--planners", compare_args.planners, "Compare these planners (comma-separated: " + PlannerList() +
                                                    ") with --strategy and --zeta, instead of the strategies")
      ->delimiter(',')
      ->check(CLI::IsMember(PlannerNames()));
  c->add_option("--routings", compare_args.routings, "Compare these routings too (comma-separated: floyd, heat)")
      ->delimiter(',')
      ->check(CLI::IsMember(RoutingNames()));
  c->add_option("--strategy", compare_args.strategy, "Strategy of a --planners comparison")->capture_default_str()
      ->check(CLI::IsMember(AllocatorNames()));
  c->add_option("--zeta", compare_args.zeta, "Traffic weight of a --planners comparison")->capture_default_str();
  return {s, c};
}

}  // namespace dispatch::engine
