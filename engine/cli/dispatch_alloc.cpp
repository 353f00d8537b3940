// dispatch-alloc: allocate a task table on a map and print the result in the shape of the
// seed's Tables 3 and 4 (Chu2024 §4.2): task -> robots, with and without the traffic-flow
// term, the bids behind a chosen task, and which assignments changed.
//   dispatch-alloc --table ../shared/scenarios/chu2024-table2.csv            (zeta 0 vs 100)
//   dispatch-alloc --table T.csv --strategy greedy --explain T3
#include <CLI/CLI.hpp>

#include <cstdio>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "engine/cli/scenario.h"
#include "engine/dispatch/strategy.h"
#include "engine/io/map_source.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine {
namespace {

int Fail(const std::string& message) {
  std::cerr << "dispatch-alloc: " << message << "\n";
  return 1;
}

struct Run {
  double zeta = 0;
  std::vector<OrderAllocation> results;
};

std::string Team(const AwardExplanation& a) {
  std::string out;
  for (const auto& r : a.winners) out += (out.empty() ? "" : " ") + r;
  return out;
}

void PrintTable(const Run& run, const std::string& strategy) {
  std::printf("Allocation, %s, zeta = %g (leader first)\n", strategy.c_str(), run.zeta);
  std::printf("  %-6s %-16s %10s  %s\n", "task", "robots", "bid", "why");
  for (const auto& r : run.results) {
    if (!r.award.ok()) {
      std::printf("  %-6s %-16s %10s  error: %s\n", r.order_id.c_str(), "-", "-",
                  r.award.error().message.c_str());
      continue;
    }
    const AwardExplanation& a = *r.award;
    double bid = 0;
    for (const Bid& b : a.bids) {
      if (b.robot == a.winners.front()) bid = b.bid;
    }
    std::printf("  %-6s %-16s %10.2f  %s\n", r.order_id.c_str(), Team(a).c_str(), bid,
                a.reason.c_str());
  }
}

void PrintBid(const char* role, const Bid& b) {
  if (!b.priced) {
    std::printf("    %-9s %-4s B>=%7.2f  T_t=%7.2f T_d=%7.2f T_w=%6.2f F>=%.4f (part of the route: could not win)\n",
                role, b.robot.c_str(), b.bid, b.t_t, b.t_d, b.t_w, b.flow);
    return;
  }
  std::printf("    %-9s %-4s B=%8.2f  T_t=%7.2f T_d=%7.2f T_w=%6.2f F=%.4f x=%7.2f\n", role,
              b.robot.c_str(), b.bid, b.t_t, b.t_d, b.t_w, b.flow, b.x);
}

void PrintExplanation(const Run& run, const std::string& task) {
  for (const auto& r : run.results) {
    if (r.order_id != task || !r.award.ok()) continue;
    const AwardExplanation& a = *r.award;
    std::printf("  zeta = %g: %s\n", run.zeta, a.reason.c_str());
    for (const Bid& b : a.bids) {
      if (b.robot == a.winners.front()) PrintBid("leader", b);
    }
    for (std::size_t i = 1; i < a.winners.size(); ++i) {
      for (const Bid& b : a.companion_bids) {
        if (b.robot == a.winners[i]) PrintBid("companion", b);
      }
    }
  }
}

Result<Run> Allocate(std::shared_ptr<const WarehouseMap> map, std::shared_ptr<const RouteTable> routes,
                     const std::vector<FleetRobot>& robots, const std::vector<Order>& orders,
                     AllocationConfig config, double zeta, const std::string& strategy) {
  config.zeta = zeta;
  auto state = FleetState::Create(map, routes, robots, config);
  if (!state.ok()) return state.error();
  auto allocator = MakeAllocator(strategy);
  if (!allocator.ok()) return allocator.error();
  Run run;
  run.zeta = zeta;
  run.results = AllocateAll(**allocator, orders, state.value());
  return run;
}

int Main(int argc, char** argv) {
  CLI::App app{"Allocate a task table (Chu2024 Tables 3/4 shape)"};
  std::string source = "chu2024", table, strategy = "auction", explain;
  std::vector<double> zetas = {0.0, 100.0};
  AllocationConfig config;
  std::size_t robot_count = 0;
  app.add_option("--map", source, "chu2024, a .json map file or a MovingAI .map file")
      ->capture_default_str();
  app.add_option("--table", table, "Task table CSV (seed format)")->required();
  app.add_option("--strategy", strategy, "auction, greedy, exact or psoga")->capture_default_str()
      ->check(CLI::IsMember(AllocatorNames()));
  app.add_option("--zeta", zetas, "Traffic weights to compare (eq. 5)")->capture_default_str();
  app.add_option("--alpha", config.alpha, "Weight of T_t (eq. 1)")->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--beta", config.beta, "Weight of T_d (eq. 1)")->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--speed", config.speed, "Robot speed v, m/s")->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--robots", robot_count, "Robots R1..Rn in stations P1..Pn (0 = one each)")
      ->capture_default_str();
  app.add_option("--drop-time", config.drop_time,
                 "Seconds worked at a drop (default: the order's t_w; 0: the seed's model, eq. 3)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--explain", explain, "Task whose bids to print (default: the last formation task)");
  CLI11_PARSE(app, argc, argv);

  auto loaded = LoadMapSource(source);
  if (!loaded.ok()) return Fail(loaded.error().message);
  auto map = std::make_shared<const WarehouseMap>(std::move(loaded).value());
  auto orders = LoadTaskTableOrders(*map, table);
  if (!orders.ok()) return Fail(orders.error().message);
  auto robots = RobotsAtStations(*map, robot_count);
  if (!robots.ok()) return Fail(robots.error().message);
  RouteTableOptions route_options;
  route_options.speed = config.speed;
  auto routes = MakeRouteTable(map, route_options);
  if (!routes.ok()) return Fail(routes.error().message);
  std::shared_ptr<const RouteTable> shared_routes = std::move(routes).value();

  std::vector<Run> runs;
  for (double zeta : zetas) {
    auto run = Allocate(map, shared_routes, *robots, *orders, config, zeta, strategy);
    if (!run.ok()) return Fail(run.error().message);
    PrintTable(*run, strategy);
    runs.push_back(std::move(run).value());
  }
  if (explain.empty()) {
    for (const Order& o : *orders) {
      if (o.formation) explain = o.id;
    }
    if (explain.empty() && !orders->empty()) explain = orders->back().id;
  }
  std::printf("Bids behind %s (companions: cost to reach the first pick)\n", explain.c_str());
  for (const Run& run : runs) PrintExplanation(run, explain);
  if (runs.size() >= 2) {
    std::map<std::string, std::string> first;
    for (const auto& r : runs.front().results) {
      if (r.award.ok()) first[r.order_id] = Team(*r.award);
    }
    int changed = 0;
    std::printf("Changed between zeta = %g and zeta = %g:\n", runs.front().zeta, runs.back().zeta);
    for (const auto& r : runs.back().results) {
      if (!r.award.ok()) continue;
      const std::string now = Team(*r.award);
      if (first[r.order_id] != now) {
        std::printf("  %s: %s -> %s\n", r.order_id.c_str(), first[r.order_id].c_str(), now.c_str());
        ++changed;
      }
    }
    if (changed == 0) std::printf("  none\n");
  }
  int failed = 0;
  for (const Run& run : runs) {
    for (const auto& r : run.results) failed += !r.award.ok();
  }
  return failed == 0 ? 0 : 2;
}

}  // namespace
}  // namespace dispatch::engine

int main(int argc, char** argv) { return dispatch::engine::Main(argc, argv); }
