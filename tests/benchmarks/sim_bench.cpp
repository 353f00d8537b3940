// sim_bench: order streams on the dispatch core driven by in-process robots
// (engine/sim/core_stream.h, issue 15 §3) on a large generated floor, as fast as the CPU
// allows (issue 4 §5).
//
//   BM_SimulateOnCore/R   R robots on a 20 x 20-shelf grid floor (engine/map/grid_floor.h: 4 x 2
//                   cell shelves, 2-cell aisles, 122 x 82 cells, ~6800 points, lazy route
//                   table, all lanes bidirectional): the service's DispatchCore, its
//                   TrafficGate and robots following its messages, auction (zeta = 100) in a
//                   round whenever one is due, at most every 10 s, a steady stream of random
//                   orders (one every 110 / R s: about one order per robot per task duration),
//                   300 simulated seconds, dt = 0.1 s. (Named "OnCore" since the older
//                   order-stream model's BM_Simulate/R, which the core was measured against
//                   until that model was deleted.)
//   BM_SimulateFormationsOnCore/R   the same with 10% of the orders formation orders (3 robots
//                   each, Chu2024 §3.2: gathering, one agent with the formation's envelope).
//   BM_SimulatePlannerTimeWindows/R, BM_SimulatePlannerConflictElimination/R,
//   BM_SimulatePlannerHeat/R   BM_SimulateOnCore's stream with AllocationConfig::planner =
//                   time-windows / conflict-elimination / routing = heat (issue 16).
//   BM_SimulateStrategyPsoGa/R, BM_SimulateStrategyExact/R   BM_SimulateOnCore's stream allocated
//                   by PSO-GA / the exact assignment (issue 17 §1): each round's pending orders
//                   (10 s of them) as one batch.
// Counter `speedup` = simulated seconds per wall second (target: R = 500 at >= 100x);
// `distance` metres driven, `alloc_s` wall seconds in allocation rounds.
// The map, the route table (warmed on every pick and drop) and the orders are built once,
// outside the timing. Run from a Release build:
//   cmake --build build-rel --target sim_bench && build-rel/tests/benchmarks/sim_bench
#include <benchmark/benchmark.h>

#include <memory>
#include <stdexcept>

#include "engine/map/grid_floor.h"
#include "engine/routing/route_table.h"
#include "engine/sim/core_stream.h"
#include "engine/sim/fleet_placement.h"
#include "engine/sim/random_orders.h"

namespace dispatch::engine {
namespace {

constexpr double kHorizon = 300.0;

struct Floor {
  std::shared_ptr<const WarehouseMap> map;
  std::shared_ptr<const RouteTable> routes;
};

const Floor& LargeFloor() {
  static const Floor floor = [] {
    auto m = BuildGridFloor({});
    if (!m.ok()) throw std::runtime_error(m.error().message);
    Floor f;
    f.map = std::make_shared<const WarehouseMap>(std::move(m).value());
    auto t = MakeRouteTable(f.map, {});
    if (!t.ok()) throw std::runtime_error(t.error().message);
    f.routes = std::move(t).value();
    // Warm the lazy table's per-destination searches on every stop.
    PointId any = 0;
    for (std::size_t p = 0; p < f.map->point_count(); ++p) {
      if (IsServicePoint(f.map->points()[p].kind)) {
        benchmark::DoNotOptimize(f.routes->Cost(any, static_cast<PointId>(p)));
      }
    }
    return f;
  }();
  return floor;
}

void Simulate(benchmark::State& state, double formation_share, PlannerKind planner = PlannerKind::kRules,
              RoutingKind routing = RoutingKind::kFloyd,
              AllocationStrategy strategy = AllocationStrategy::kAuction) {
  const Floor& f = LargeFloor();
  const auto robots_count = static_cast<std::size_t>(state.range(0));
  auto robots = PlaceRobots(*f.map, robots_count);
  if (!robots.ok()) throw std::runtime_error(robots.error().message);
  RandomOrderOptions ro;
  ro.interval = 110.0 / static_cast<double>(robots_count);
  ro.count = static_cast<std::size_t>(kHorizon / ro.interval);
  ro.seed = 42;
  ro.formation_share = formation_share;
  auto orders = RandomOrders(*f.map, ro);
  if (!orders.ok()) throw std::runtime_error(orders.error().message);
  StreamConfig config;
  config.max_time = kHorizon;
  config.allocation_period = 10.0;
  config.strategy = strategy;
  config.allocation.planner = planner;
  config.allocation.routing = routing;
  config.traffic.execution = DefaultPlanExecution(planner);  // as dispatchd and dispatch-sim drive it
  double simulated = 0;
  std::size_t completed = 0, total = 0, deadlocks = 0, replans = 0, blocked = 0;
  double waiting = 0.0, completion = 0.0, recovered = 0.0, head_on = 0.0, distance = 0.0, planning = 0.0;
  for (auto _ : state) {
    auto r = SimulateOnCore(f.map, f.routes, *robots, *orders, config);
    if (!r.ok()) throw std::runtime_error(r.error().message);
    simulated += r->end_time;
    completed += r->completed;
    total += r->orders.size();
    deadlocks += r->traffic.deadlocks_resolved;
    replans += r->traffic.replans;
    blocked += r->blocked.size();
    waiting += r->total_waiting_time;
    completion += r->mean_completion;
    recovered += static_cast<double>(r->recovered.size());
    head_on += static_cast<double>(r->traffic.head_on_conflicts);
    distance += r->total_distance;
    planning += r->planning_seconds;
  }
  state.counters["speedup"] = benchmark::Counter(simulated, benchmark::Counter::kIsRate);
  state.counters["completed"] = static_cast<double>(completed) / static_cast<double>(state.iterations());
  state.counters["orders"] = static_cast<double>(total) / static_cast<double>(state.iterations());
  state.counters["deadlocks"] = static_cast<double>(deadlocks) / static_cast<double>(state.iterations());
  state.counters["replans"] = static_cast<double>(replans) / static_cast<double>(state.iterations());
  state.counters["blocked"] = static_cast<double>(blocked) / static_cast<double>(state.iterations());
  // Robot-seconds held by the traffic control, and the mean release-to-completion time (s).
  state.counters["waiting"] = waiting / static_cast<double>(state.iterations());
  state.counters["mean_done"] = completion / static_cast<double>(state.iterations());
  state.counters["head_on"] = head_on / static_cast<double>(state.iterations());
  state.counters["recovered"] = recovered / static_cast<double>(state.iterations());
  // Metres driven, and wall seconds spent in allocation rounds (strategy and planner).
  state.counters["distance"] = distance / static_cast<double>(state.iterations());
  state.counters["alloc_s"] = planning / static_cast<double>(state.iterations());
}

void BM_SimulateOnCore(benchmark::State& state) { Simulate(state, 0.0); }
void BM_SimulateFormationsOnCore(benchmark::State& state) { Simulate(state, 0.1); }
void BM_SimulatePlannerTimeWindows(benchmark::State& state) { Simulate(state, 0.0, PlannerKind::kTimeWindows); }
void BM_SimulatePlannerConflictElimination(benchmark::State& state) {
  Simulate(state, 0.0, PlannerKind::kConflictElimination);
}
void BM_SimulatePlannerHeat(benchmark::State& state) { Simulate(state, 0.0, PlannerKind::kRules, RoutingKind::kHeat); }
void BM_SimulateStrategyPsoGa(benchmark::State& state) {
  Simulate(state, 0.0, PlannerKind::kRules, RoutingKind::kFloyd, AllocationStrategy::kPsoGa);
}
void BM_SimulateStrategyExact(benchmark::State& state) {
  Simulate(state, 0.0, PlannerKind::kRules, RoutingKind::kFloyd, AllocationStrategy::kExact);
}
BENCHMARK(BM_SimulateOnCore)->Arg(18)->Arg(100)->Arg(500)->Unit(benchmark::kMillisecond)
    ->UseRealTime()->Iterations(2);
BENCHMARK(BM_SimulateFormationsOnCore)->Arg(100)->Arg(500)->Unit(benchmark::kMillisecond)
    ->UseRealTime()->Iterations(2);
BENCHMARK(BM_SimulatePlannerTimeWindows)->Arg(100)->Arg(500)->Unit(benchmark::kMillisecond)
    ->UseRealTime()->Iterations(2);
BENCHMARK(BM_SimulatePlannerConflictElimination)->Arg(100)->Arg(500)->Unit(benchmark::kMillisecond)
    ->UseRealTime()->Iterations(2);
BENCHMARK(BM_SimulatePlannerHeat)->Arg(100)->Arg(500)->Unit(benchmark::kMillisecond)
    ->UseRealTime()->Iterations(2);
BENCHMARK(BM_SimulateStrategyPsoGa)->Arg(100)->Arg(500)->Unit(benchmark::kMillisecond)
    ->UseRealTime()->Iterations(2);
BENCHMARK(BM_SimulateStrategyExact)->Arg(100)->Arg(500)->Unit(benchmark::kMillisecond)
    ->UseRealTime()->Iterations(2);

}  // namespace
}  // namespace dispatch::engine

BENCHMARK_MAIN();
