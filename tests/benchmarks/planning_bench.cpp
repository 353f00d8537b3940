// Conflict-free planning benchmarks (issue 16 §2, SPEC §3.6): BIT2024 step 7's conflict
// elimination beside CBS (the optimal yardstick) and the independent shortest paths (the
// lower bound on the sum of costs), on one floor and the same agents.
//   BM_IndependentPaths/N, BM_ConflictElimination/N, BM_Cbs/N: N agents with random distinct
//   starts and goals (seed 7) on a 6 x 6-shelf grid floor (engine/map/grid_floor.h: 4 x 2
//   cell shelves, 2-cell aisles, 38 x 26 cells of which 700 free, unit-time moves between
//   adjacent cells).
//   Each run has a 10 s budget (PlanLimits via DeadlineCheck).
// Counters: solved (1/0), soc (sum of costs, steps; 0 when unsolved), lower_bound (the sum
// of the agents' shortest paths alone), conflicts (independent paths only), nodes (CBS: tree nodes; elimination: conflicts
// eliminated), searches (single-agent searches); an unsolved run's label says why.
//   BM_TimeWindowFleet/N: N robots planned one by one in priority order into an empty
//   ReservationTable (engine/planning/window_planner.h, Wang2019's time windows): each from a
//   random start to a random pick (2 s work) and a random drop where it stays, on a
//   16 x 24-shelf grid floor (98 x 98 cells, 6,532 free; all lanes bidirectional single lanes).
//   BM_TimeWindowPlan/N: one more robot planned into the table holding those N robots' windows
//   (issue 16's target: N = 500 at <= 1 ms median), over a pool of 64 requests; the route table
//   (lazy) is warmed on the requests' stops first, as the service's is on its pick and drop points.
//   Counters: median_ms (per plan), planned / failed, expanded (SIPP states per plan).
//   BM_HybridAStar/<variant>: BIT2024 step 6's hybrid A* for 4WIS robots (SPEC §3.7,
//   engine/motion/hybrid_astar.h) on the narrow-area floor (engine/motion/narrow_floor.h:
//   12 x 6 m, 0.1 m cells, robot 0.8 x 0.5 m, turning radius 0.8 m), the cross-floor query
//   (corridor (0.8, 0.8, 0) -> hall upper lane (2.0, 5.1, pi)), default options. Variants:
//   narrow (4WIS, adaptive xi, eq. (6)), narrow_fixed_xi (xi = 1 everywhere),
//   narrow_baseline (crab and spin off: the car / differential-drive baseline),
//   narrow_plain_manhattan (eq. (5)'s h_o as plain |dx| + |dy| instead of through free cells).
//   Target (issue 17 §2): narrow <= 50 ms median. Counters: nodes (expanded), length (m),
//   rotation (rad turned in place), switches (drive-class changes), solved.
//   BM_MotionConflictElimination/N: BIT2024 step 7 over those paths
//   (engine/motion/motion_conflict_elimination.h): N robots between the narrow floor's
//   stations, seeds 1-8, each with a 10 s budget; the time is all 8. Counters: solved (of 8),
//   rounds (mean over the solved), makespan (mean last arrival, s, solved runs) beside
//   alone_makespan (the same robots' paths planned alone, conflicts ignored: the lower bound).
// Run from a Release build:
//   cmake --build build-bench --target planning_bench && build-bench/tests/benchmarks/planning_bench
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>

#include "engine/map/grid_floor.h"
#include "engine/motion/hybrid_astar.h"
#include "engine/motion/motion_conflict_elimination.h"
#include "engine/motion/narrow_floor.h"
#include "engine/planning/cbs.h"
#include "engine/planning/conflict_elimination.h"
#include "engine/planning/space_time_astar.h"
#include "engine/planning/window_planner.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine {
namespace {

const MapfGraph& Floor() {
  static const MapfGraph graph = [] {
    GridFloorOptions options;
    options.shelf_rows = 6;
    options.shelf_cols = 6;
    auto map = BuildGridFloor(options);
    if (!map.ok()) throw std::runtime_error(map.error().message);
    return MapfGraph::FromMap(map.value());
  }();
  return graph;
}

// n agents on distinct starts and distinct goals (seed 7), on the floor's connected part.
std::vector<MapfAgent> Agents(std::size_t n) {
  auto agents = RandomAgents(Floor().PartOf(0), n, 7);
  if (!agents.ok()) throw std::runtime_error(agents.error().message);
  return std::move(agents).value();
}

int LowerBound(const std::vector<MapfAgent>& agents) {
  int sum = 0;
  for (const MapfAgent& a : agents) sum += Floor().StepsTo(a.goal)[static_cast<std::size_t>(a.start)];
  return sum;
}

template <class Solve>
void Run(benchmark::State& state, Solve solve) {
  const auto agents = Agents(static_cast<std::size_t>(state.range(0)));
  Result<MapfSolution> last = MapfSolution{};
  for (auto _ : state) {
    last = solve(agents, DeadlineCheck(std::chrono::seconds(10)));
    benchmark::DoNotOptimize(last);
  }
  state.counters["solved"] = last.ok() ? 1 : 0;
  state.counters["soc"] = last.ok() ? last.value().sum_of_costs : 0;
  state.counters["lower_bound"] = LowerBound(agents);
  if (!last.ok()) state.SetLabel(last.error().message.substr(0, 90));
  if (last.ok()) {
    if (!CheckPaths(Floor(), agents, last.value().paths).ok()) throw std::logic_error("infeasible paths");
    state.counters["nodes"] = static_cast<double>(last.value().nodes);
    state.counters["searches"] = static_cast<double>(last.value().searches);
  }
}

// Each agent's shortest path alone: the time of the searches and how many conflicts they leave.
void BM_IndependentPaths(benchmark::State& state) {
  const auto agents = Agents(static_cast<std::size_t>(state.range(0)));
  std::vector<TimedPath> paths;
  for (auto _ : state) {
    paths.clear();
    for (const MapfAgent& a : agents) {
      auto found = PlanAgent(Floor(), Floor().StepsTo(a.goal), a.start, a.goal, {});
      if (!found.ok()) throw std::runtime_error(found.error().message);
      paths.push_back(std::move(found.value().path));
    }
  }
  state.counters["soc"] = SumOfCosts(paths);
  state.counters["lower_bound"] = LowerBound(agents);
  state.counters["conflicts"] = CountConflicts(paths, Floor().size());
}

void BM_ConflictElimination(benchmark::State& state) {
  Run(state, [](const std::vector<MapfAgent>& agents, std::function<bool()> stop) {
    ConflictEliminationOptions options;
    options.limits.stop = std::move(stop);
    return EliminateConflicts(Floor(), agents, options);
  });
}

void BM_Cbs(benchmark::State& state) {
  Run(state, [](const std::vector<MapfAgent>& agents, std::function<bool()> stop) {
    PlanLimits limits;
    limits.stop = std::move(stop);
    return SolveCbs(Floor(), agents, limits);
  });
}

struct WindowFloor {
  std::shared_ptr<const WarehouseMap> map;
  std::unique_ptr<RouteTable> routes;
};

const WindowFloor& LargeWindowFloor() {
  static const WindowFloor floor = [] {
    GridFloorOptions options;
    options.shelf_rows = 24;
    options.shelf_cols = 16;
    auto map = BuildGridFloor(options);
    if (!map.ok()) throw std::runtime_error(map.error().message);
    WindowFloor f;
    f.map = std::make_shared<const WarehouseMap>(std::move(map).value());
    auto routes = MakeRouteTable(f.map, {});
    if (!routes.ok()) throw std::runtime_error(routes.error().message);
    f.routes = std::move(routes).value();
    return f;
  }();
  return floor;
}

// n requests: distinct starts and distinct drops (where they stay), random picks; release
// times spread over a minute. Points that are starts or drops are never picks.
std::vector<WindowRequest> WindowRequests(std::size_t n, std::uint64_t seed) {
  const WindowFloor& f = LargeWindowFloor();
  std::vector<PointId> cells(f.map->point_count());
  for (std::size_t i = 0; i < cells.size(); ++i) cells[i] = static_cast<PointId>(i);
  std::mt19937_64 random(seed);
  std::shuffle(cells.begin(), cells.end(), random);
  std::vector<WindowRequest> out;
  for (std::size_t i = 0; i < n; ++i) {
    WindowRequest r;
    r.robot = static_cast<int>(i);
    r.start = cells[i];
    r.stops = {{cells[2 * n + random() % (cells.size() - 2 * n)], 2.0}, {cells[n + i], 2.0}};
    r.release_time = static_cast<double>(random() % 60);
    out.push_back(r);
  }
  return out;
}

void BM_TimeWindowFleet(benchmark::State& state) {
  const WindowFloor& f = LargeWindowFloor();
  const auto requests = WindowRequests(static_cast<std::size_t>(state.range(0)), 11);
  for (const auto& r : requests) f.routes->Prepare(r.stops[0].point), f.routes->Prepare(r.stops[1].point);
  std::size_t planned = 0, expanded = 0;
  for (auto _ : state) {
    ReservationTable table(f.map, {});
    auto plans = PlanInPriorityOrder(table, *f.routes, requests);
    if (!plans.ok()) throw std::runtime_error(plans.error().message);
    planned = 0;
    for (const auto& r : plans.value().routes) planned += r.empty() ? 0 : 1;
    expanded = plans.value().expanded;
  }
  state.counters["planned"] = static_cast<double>(planned);
  state.counters["failed"] = static_cast<double>(requests.size() - planned);
  state.counters["expanded"] = static_cast<double>(expanded) / static_cast<double>(requests.size());
}

void BM_TimeWindowPlan(benchmark::State& state) {
  const WindowFloor& f = LargeWindowFloor();
  const auto n = static_cast<std::size_t>(state.range(0));
  auto requests = WindowRequests(n + 64, 11);
  const std::vector<WindowRequest> fleet(requests.begin(), requests.begin() + static_cast<long>(n));
  std::vector<WindowRequest> pool(requests.begin() + static_cast<long>(n), requests.end());
  for (const auto& r : requests) f.routes->Prepare(r.stops[0].point), f.routes->Prepare(r.stops[1].point);
  ReservationTable table(f.map, {});
  if (!PlanInPriorityOrder(table, *f.routes, fleet).ok()) throw std::runtime_error("fleet not planned");
  std::vector<double> ms;
  std::size_t k = 0, failed = 0, expanded = 0;
  for (auto _ : state) {
    WindowRequest r = pool[k++ % pool.size()];
    r.start_time = 0.0;
    const auto t0 = std::chrono::steady_clock::now();
    auto plan = PlanInWindows(table, *f.routes, r);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    if (plan.ok()) {
      expanded += plan.value().expanded;
    } else {
      ++failed;
    }
  }
  std::nth_element(ms.begin(), ms.begin() + static_cast<long>(ms.size() / 2), ms.end());
  state.counters["median_ms"] = ms[ms.size() / 2];
  state.counters["failed"] = static_cast<double>(failed) / static_cast<double>(state.iterations());
  const auto solved = static_cast<double>(state.iterations()) - static_cast<double>(failed);
  state.counters["expanded"] = solved > 0 ? static_cast<double>(expanded) / solved : 0.0;
}

enum class HybridVariant { kAdaptive, kFixedXi, kBaseline, kPlainManhattan };

void BM_HybridAStar(benchmark::State& state, HybridVariant variant) {
  static const NarrowFloor floor = BuildNarrowFloor();
  static const FootprintChecker checker(floor.grid, floor.footprint);
  HybridAStarOptions options;
  options.min_turn_radius = floor.min_turn_radius;
  options.adaptive_xi = variant != HybridVariant::kFixedXi;
  options.fixed_xi = 1.0;
  options.allow_crab = options.allow_spin = variant != HybridVariant::kBaseline;
  options.manhattan_through_free_cells = variant != HybridVariant::kPlainManhattan;
  Result<MotionPath> last = MotionPath{};
  for (auto _ : state) {
    options.limits.stop = DeadlineCheck(std::chrono::seconds(10));
    last = PlanHybridAStar(checker, floor.cross_start, floor.cross_goal, options);
    benchmark::DoNotOptimize(last);
  }
  state.counters["solved"] = last.ok() ? 1 : 0;
  if (!last.ok()) {
    state.SetLabel(last.error().message.substr(0, 90));
    return;
  }
  state.counters["nodes"] = static_cast<double>(last.value().nodes_expanded);
  state.counters["length"] = last.value().length;
  state.counters["rotation"] = last.value().rotation;
  state.counters["switches"] = last.value().switches;
}

BENCHMARK_CAPTURE(BM_HybridAStar, narrow, HybridVariant::kAdaptive)
    ->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);
BENCHMARK_CAPTURE(BM_HybridAStar, narrow_fixed_xi, HybridVariant::kFixedXi)
    ->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);
BENCHMARK_CAPTURE(BM_HybridAStar, narrow_baseline, HybridVariant::kBaseline)
    ->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);
BENCHMARK_CAPTURE(BM_HybridAStar, narrow_plain_manhattan, HybridVariant::kPlainManhattan)
    ->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(3)->ReportAggregatesOnly(true);

void BM_MotionConflictElimination(benchmark::State& state) {
  static const NarrowFloor floor = BuildNarrowFloor();
  const auto n = static_cast<std::size_t>(state.range(0));
  double solved = 0, rounds = 0, makespan = 0, alone = 0;
  for (auto _ : state) {
    solved = rounds = makespan = alone = 0;
    for (std::uint64_t seed = 1; seed <= 8; ++seed) {
      auto robots = NarrowFloorRobots(floor, n, seed);
      if (!robots.ok()) throw std::runtime_error(robots.error().message);
      MotionConflictEliminationOptions options;
      options.seed = seed;
      options.planner.min_turn_radius = floor.min_turn_radius;
      options.limits.stop = DeadlineCheck(std::chrono::seconds(10));
      auto fleet = EliminateMotionConflicts(floor.grid, *robots, options);
      if (!fleet.ok()) continue;
      solved += 1;
      rounds += static_cast<double>(fleet->rounds);
      double last = 0, last_alone = 0;
      for (std::size_t i = 0; i < n; ++i) {
        last = std::max(last, fleet->paths[i].arrival());
        HybridAStarOptions alone_options = options.planner;
        alone_options.limits = {};
        auto path = PlanHybridAStar(FootprintChecker(floor.grid, floor.footprint), (*robots)[i].start,
                                    (*robots)[i].goal, alone_options);
        if (path.ok()) last_alone = std::max(last_alone, TimeMotionPath(*path, 0.0, options.timing).arrival());
      }
      makespan += last;
      alone += last_alone;
    }
  }
  state.counters["solved"] = solved;
  state.counters["rounds"] = solved > 0 ? rounds / solved : 0;
  state.counters["makespan"] = solved > 0 ? makespan / solved : 0;
  state.counters["alone_makespan"] = solved > 0 ? alone / solved : 0;
}

BENCHMARK(BM_MotionConflictElimination)->Arg(2)->Arg(3)->Arg(4)->Unit(benchmark::kMillisecond)->Iterations(1);

BENCHMARK(BM_IndependentPaths)->Arg(10)->Arg(50)->Arg(100)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ConflictElimination)->Arg(10)->Arg(50)->Arg(100)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_Cbs)->Arg(10)->Arg(50)->Arg(100)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_TimeWindowFleet)->Arg(100)->Arg(500)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_TimeWindowPlan)->Arg(100)->Arg(500)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace dispatch::engine

BENCHMARK_MAIN();
