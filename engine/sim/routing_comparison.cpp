#include "engine/sim/routing_comparison.h"

#include <memory>
#include <utility>
#include <vector>

#include "engine/map/grid_floor.h"
#include "engine/routing/route_table.h"
#include "engine/sim/core_stream.h"
#include "engine/sim/fleet_placement.h"
#include "engine/sim/random_orders.h"

namespace dispatch::engine {
namespace {

Result<RoutingRun> RunRouting(std::shared_ptr<const WarehouseMap> map, const std::vector<FleetRobot>& robots,
                           const std::vector<Order>& orders, const RoutingComparisonOptions& o, bool improved) {
  RouteTableOptions table;
  table.turn_penalty_s = improved ? o.turn_time : 0.0;
  table.method = RouteTableMethod::kLazy;  // Dijkstra per destination, as the seed; few are asked
  auto routes = MakeRouteTable(map, table);
  if (!routes.ok()) return routes.error();
  StreamConfig config;
  config.allocation.turn_time = o.turn_time;
  config.allocation.routing = improved ? RoutingKind::kHeat : RoutingKind::kFloyd;
  config.max_time = 3600.0;
  config.check_safety = false;
  auto r = SimulateOnCore(map, std::move(routes).value(), robots, orders, config);
  if (!r.ok()) return r.error();
  RoutingRun run;
  run.completed = r->completed;
  run.total_distance = r->total_distance;
  run.makespan = r->makespan;
  run.waiting = r->total_waiting_time;
  run.replans = r->traffic.replans;
  for (const StreamOrderOutcome& oc : r->orders) {
    if (oc.completed) {
      run.total_time += oc.completion_time - oc.release_time;
    } else {
      run.failures.push_back(oc.order_id + ": " + oc.failure);
    }
  }
  return run;
}

}  // namespace

Result<RoutingComparison> RunRoutingComparison(const RoutingComparisonOptions& o) {
  if (o.tasks == 0) return InvalidArgument("routing comparison: tasks must be >= 1");
  if (!(o.turn_time >= 0.0)) return InvalidArgument("routing comparison: turn_time must be >= 0");
  auto built = BuildWang2019Floor();
  if (!built.ok()) return built.error();
  auto map = std::make_shared<const WarehouseMap>(std::move(built).value());
  auto robots = PlaceRobots(*map, o.tasks);
  if (!robots.ok()) return robots.error();
  RandomOrderOptions ro;
  ro.count = o.tasks;
  ro.seed = o.seed;
  ro.interval = 0.0;
  ro.work_time = o.work_time;
  auto orders = RandomOrders(*map, ro);
  if (!orders.ok()) return orders.error();
  RoutingComparison out;
  out.tasks = o.tasks;
  out.seed = o.seed;
  for (auto [improved, slot] : {std::pair{false, &out.traditional}, std::pair{true, &out.improved}}) {
    auto run = RunRouting(map, *robots, *orders, o, improved);
    if (!run.ok()) return run.error();
    *slot = *run;
  }
  return out;
}

}  // namespace dispatch::engine
