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
// Run from a Release build:
//   cmake --build build-bench --target planning_bench && build-bench/tests/benchmarks/planning_bench
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>

#include "engine/map/grid_floor.h"
#include "engine/planning/cbs.h"
#include "engine/planning/conflict_elimination.h"
#include "engine/planning/space_time_astar.h"

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

// n agents on distinct starts and distinct goals, all on the floor's largest component
// (a cell that reaches vertex 0; the grid floor is connected).
std::vector<MapfAgent> Agents(std::size_t n) {
  const MapfGraph& g = Floor();
  const std::vector<int> reach = g.StepsTo(0);
  std::vector<PointId> cells;
  for (std::size_t v = 0; v < g.size(); ++v) {
    if (reach[v] != MapfGraph::kUnreachable) cells.push_back(static_cast<PointId>(v));
  }
  std::mt19937_64 random(7);
  std::vector<PointId> starts = cells, goals = cells;
  std::shuffle(starts.begin(), starts.end(), random);
  std::shuffle(goals.begin(), goals.end(), random);
  std::vector<MapfAgent> agents;
  for (std::size_t i = 0; i < n; ++i) agents.push_back({starts[i], goals[i]});
  return agents;
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

BENCHMARK(BM_IndependentPaths)->Arg(10)->Arg(50)->Arg(100)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ConflictElimination)->Arg(10)->Arg(50)->Arg(100)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_Cbs)->Arg(10)->Arg(50)->Arg(100)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
}  // namespace dispatch::engine

BENCHMARK_MAIN();
