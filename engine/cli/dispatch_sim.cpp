// dispatch-sim: allocate a task table with the auction on the Chu2024 floor (R1..R18 at their
// stations), simulate the plans with traffic rules off and/or on, and print per-order
// completion times, makespan and the minimum pairwise robot distance (seed 000 Fig. 8).
//   dispatch-sim --table ../shared/scenarios/chu2024-table1.csv --rules both --csv fig8.csv
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "engine/allocation/auction_allocator.h"
#include "engine/cli/map_source.h"
#include "engine/cli/scenario.h"
#include "engine/routing/route_table.h"
#include "engine/sim/simulator.h"
#include "engine/traffic/safety_check.h"

namespace dispatch::engine {
namespace {

int Fail(const std::string& message) {
  std::cerr << "dispatch-sim: " << message << "\n";
  return 1;
}

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

int Main(int argc, char** argv) {
  CLI::App app{"Simulate a task table on the Chu2024 floor (seed 000 Fig. 8)"};
  std::string table, rules = "both", csv;
  double zeta = 100.0;
  AllocationConfig config;
  SimConfig sim;
  app.add_option("--table", table, "Task table CSV (seed format)")->required();
  app.add_option("--zeta", zeta, "Traffic weight of the auction (eq. 5)")->capture_default_str();
  app.add_option("--rules", rules, "Traffic rules: on, off or both")->capture_default_str()
      ->check(CLI::IsMember({"on", "off", "both"}));
  app.add_option("--csv", csv, "Write t,min_distance_off,min_distance_on here");
  app.add_option("--dt", sim.time_step, "Time step, s")->capture_default_str()
      ->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);

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

}  // namespace
}  // namespace dispatch::engine

int main(int argc, char** argv) { return dispatch::engine::Main(argc, argv); }
