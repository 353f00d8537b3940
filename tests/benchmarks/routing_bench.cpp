// routing_bench: all-pairs builders on random sparse road-like graphs; on large grid maps the
// lazy table's first (uncached) and cached query, and the hub label table's build (time and
// size as counters) and its Cost and NextHop between random pairs (issue 19 §1).
//
//   cmake -S . -B build-bench -DCMAKE_BUILD_TYPE=Release -DDISPATCH_BUILD_BENCHMARKS=ON
//       -DDISPATCH_BUILD_TESTS=OFF  (one line)
//   cmake --build build-bench -j1 --target routing_bench && build-bench/tests/benchmarks/routing_bench
//
// Graphs: N points on a jittered grid, numbered row by row (spatially), joined to their right
// and lower neighbours (2-4 arcs per point), about a fifth of the lanes one-way.
// RegisterLazyMapBenchmarks benchmarks any WarehouseMap (e.g. an imported MovingAI map).
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <mutex>
#include <random>
#include <string>

#include "engine/io/movingai_map.h"
#include "engine/map/chu2024_floor.h"
#include "engine/map/map_builder.h"
#include "engine/routing/dijkstra.h"
#include "engine/routing/floyd.h"
#include "engine/routing/hub_label_route_table.h"
#include "engine/routing/lazy_route_table.h"

namespace dispatch::engine {
namespace {

CostGraph RoadLikeGraph(int n, unsigned seed = 42) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
  std::vector<double> x(static_cast<std::size_t>(n)), y(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    x[static_cast<std::size_t>(i)] = i % side + 0.3 * (unit(rng) - 0.5);
    y[static_cast<std::size_t>(i)] = static_cast<double>(i / side) + 0.3 * (unit(rng) - 0.5);
  }
  std::vector<CostArc> arcs;
  auto join = [&](int a, int b) {
    if (b >= n || unit(rng) < 0.1) return;  // a few missing lanes
    const double len = std::hypot(x[static_cast<std::size_t>(a)] - x[static_cast<std::size_t>(b)],
                                  y[static_cast<std::size_t>(a)] - y[static_cast<std::size_t>(b)]);
    const double r = unit(rng);
    if (r < 0.1) {
      arcs.push_back({a, b, len});
    } else if (r < 0.2) {
      arcs.push_back({b, a, len});
    } else {
      arcs.push_back({a, b, len});
      arcs.push_back({b, a, len});
    }
  };
  for (int i = 0; i < n; ++i) {
    if ((i + 1) % side != 0) join(i, i + 1);
    join(i, i + side);
  }
  return CostGraph::Build(static_cast<std::size_t>(n), std::move(arcs)).value();
}

void SetCounters(benchmark::State& state, const CostGraph& g) {
  state.counters["vertices"] = static_cast<double>(g.vertex_count());
  state.counters["arcs"] = static_cast<double>(g.arc_count());
}

void BM_FloydTextbook(benchmark::State& state) {
  const CostGraph g = RoadLikeGraph(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(FloydTextbook(g).value().dist.data());
  SetCounters(state, g);
}

void BM_FloydBlocked(benchmark::State& state) {
  const CostGraph g = RoadLikeGraph(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(FloydBlocked(g, 2).value().dist.data());
  SetCounters(state, g);
}

void BM_FloydBlockedOneThread(benchmark::State& state) {
  const CostGraph g = RoadLikeGraph(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(FloydBlocked(g, 1).value().dist.data());
  SetCounters(state, g);
}

void BM_AllPairsDijkstra(benchmark::State& state) {
  const CostGraph g = RoadLikeGraph(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(AllPairsDijkstra(g, 2).value().dist.data());
  SetCounters(state, g);
}

#define DISPATCH_ALL_PAIRS_BENCH(fn)                                                     \
  BENCHMARK(fn)->Arg(500)->Arg(1000)->Iterations(3)->Unit(benchmark::kMillisecond)->UseRealTime(); \
  BENCHMARK(fn)->Arg(2000)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime()

DISPATCH_ALL_PAIRS_BENCH(BM_FloydTextbook);
DISPATCH_ALL_PAIRS_BENCH(BM_FloydBlocked);
DISPATCH_ALL_PAIRS_BENCH(BM_FloydBlockedOneThread);
DISPATCH_ALL_PAIRS_BENCH(BM_AllPairsDijkstra);

// A side x side grid of lanes 1 m apart, bidirectional, every 7th row one-way.
std::shared_ptr<const WarehouseMap> GridMap(int side) {
  MapBuilder b("grid" + std::to_string(side));
  b.AddRectZone("floor", {-1, -1}, {side + 1.0, side + 1.0});
  auto name = [](int x, int y) { return std::to_string(x) + "_" + std::to_string(y); };
  for (int y = 0; y < side; ++y) {
    for (int x = 0; x < side; ++x) b.AddPoint(name(x, y), {x * 1.0, y * 1.0}, PointKind::kLane);
  }
  for (int y = 0; y < side; ++y) {
    for (int x = 0; x < side; ++x) {
      if (x + 1 < side) b.AddPath(name(x, y), name(x + 1, y), std::nullopt, 0.0, y % 7 != 3);
      if (y + 1 < side) b.AddPath(name(x, y), name(x, y + 1), std::nullopt, 0.0, true);
    }
  }
  return std::make_shared<const WarehouseMap>(b.Build().value());
}

// First query towards a destination: one reverse Dijkstra (the cache keeps only the newest
// entry and destinations rotate, so every iteration misses).
void LazyFirstQuery(benchmark::State& state, std::shared_ptr<const WarehouseMap> map,
                    double turn_penalty_s) {
  RouteTableOptions options;
  options.turn_penalty_s = turn_penalty_s;
  options.lazy_cache_bytes = 1;
  const auto table = LazyRouteTable::Build(map, options).value();
  const auto n = static_cast<PointId>(map->point_count());
  PointId to = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(table->Cost(0, to));
    to = (to + 7919) % n;
  }
  state.counters["vertices"] = static_cast<double>(table->build_info().vertex_count);
  // One cached destination: a distance and a first arc per searched vertex.
  state.counters["bytes_per_destination"] =
      static_cast<double>(table->build_info().vertex_count * 12);
}

// Cached queries: Cost from rotating sources to one warmed-up destination.
void LazyCachedQuery(benchmark::State& state, std::shared_ptr<const WarehouseMap> map,
                     double turn_penalty_s) {
  RouteTableOptions options;
  options.turn_penalty_s = turn_penalty_s;
  const auto table = LazyRouteTable::Build(map, options).value();
  const auto n = static_cast<PointId>(map->point_count());
  const PointId to = n / 2;
  benchmark::DoNotOptimize(table->Cost(0, to));
  PointId from = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(table->Cost(from, to));
    from = (from + 104729) % n;
  }
}

// The production route table of the built-in Chu2024 floor (what dispatchd builds at start).
void BM_Chu2024FloydRouteTable(benchmark::State& state) {
  const auto map = std::make_shared<const WarehouseMap>(BuildChu2024Floor().value());
  RouteTableOptions options;
  options.method = RouteTableMethod::kFloyd;
  for (auto _ : state) benchmark::DoNotOptimize(MakeRouteTable(map, options).value().get());
  state.counters["points"] = static_cast<double>(map->point_count());
  state.counters["arcs"] = static_cast<double>(map->arcs().size());
}
BENCHMARK(BM_Chu2024FloydRouteTable)->Unit(benchmark::kMillisecond)->UseRealTime();

// One hub label table per map, built on first use (so that a filtered run builds none).
struct LabelledMap {
  std::shared_ptr<const WarehouseMap> map;
  std::once_flag once;
  std::unique_ptr<HubLabelRouteTable> table;
  const HubLabelRouteTable& Get() {
    std::call_once(once, [this] { table = HubLabelRouteTable::Build(map, {}).value(); });
    return *table;
  }
};

// The build: wall time, and the labels' size as counters.
void HubLabelBuild(benchmark::State& state, std::shared_ptr<const WarehouseMap> map) {
  std::unique_ptr<HubLabelRouteTable> table;
  for (auto _ : state) table = HubLabelRouteTable::Build(map, {}).value();
  const HubLabelStats& s = table->label_stats();
  const double vertices = static_cast<double>(table->build_info().vertex_count);
  state.counters["vertices"] = vertices;
  state.counters["shortcuts"] = static_cast<double>(s.shortcuts);
  state.counters["mean_label"] = static_cast<double>(s.label_entries) / (2.0 * vertices);
  state.counters["max_label"] = static_cast<double>(s.max_label);
  state.counters["MiB"] = static_cast<double>(s.bytes) / (1 << 20);
  state.counters["contract_s"] = s.contract_seconds;
  state.counters["label_s"] = s.label_seconds;
}

// Cost or NextHop between random pairs: no pair is cheaper for having been asked before.
void HubLabelQuery(benchmark::State& state, std::shared_ptr<LabelledMap> labelled, bool next_hop) {
  const HubLabelRouteTable& table = labelled->Get();
  std::mt19937 rng(7);
  std::uniform_int_distribution<PointId> pick(0, static_cast<PointId>(table.point_count()) - 1);
  for (auto _ : state) {
    const PointId from = pick(rng), to = pick(rng);
    if (next_hop) {
      benchmark::DoNotOptimize(table.NextHop(from, to));
    } else {
      benchmark::DoNotOptimize(table.Cost(from, to));
    }
  }
}

}  // namespace

// Registers BM_HubLabelBuild/<name>, BM_HubLabelCost/<name> and BM_HubLabelNextHop/<name>.
void RegisterHubLabelBenchmarks(const std::string& name, std::shared_ptr<const WarehouseMap> map) {
  auto labelled = std::make_shared<LabelledMap>();
  labelled->map = map;
  benchmark::RegisterBenchmark(("BM_HubLabelBuild/" + name).c_str(), HubLabelBuild, map)
      ->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();
  benchmark::RegisterBenchmark(("BM_HubLabelCost/" + name).c_str(), HubLabelQuery, labelled, false)
      ->Unit(benchmark::kNanosecond);
  benchmark::RegisterBenchmark(("BM_HubLabelNextHop/" + name).c_str(), HubLabelQuery, labelled, true)
      ->Unit(benchmark::kNanosecond);
}

// Registers BM_LazyFirstQuery/<name> and BM_LazyCachedQuery/<name> for `map` (with and
// without turn penalty).
void RegisterLazyMapBenchmarks(const std::string& name, std::shared_ptr<const WarehouseMap> map) {
  for (double penalty : {0.0, 2.0}) {
    const std::string suffix = name + (penalty > 0 ? "/turns" : "");
    benchmark::RegisterBenchmark(("BM_LazyFirstQuery/" + suffix).c_str(), LazyFirstQuery, map,
                                 penalty)
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("BM_LazyCachedQuery/" + suffix).c_str(), LazyCachedQuery, map,
                                 penalty)
        ->Unit(benchmark::kNanosecond);
  }
}

}  // namespace dispatch::engine

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  const auto grid = dispatch::engine::GridMap(300);
  dispatch::engine::RegisterLazyMapBenchmarks("grid300x300", grid);
  dispatch::engine::RegisterHubLabelBenchmarks("grid300x300", grid);
  // The public LoRR floors (38,586 and 54,320 free cells), when ../shared is where the build
  // expects it.
  for (const char* floor : {"warehouse_large", "sortation_large"}) {
    const std::string file = std::string(DISPATCH_SHARED_DIR) +
        "/benchmarks/lorr2024/example_problems/warehouse.domain/maps/" + floor + ".map";
    auto map = dispatch::engine::LoadMovingAiMapFile(file);
    if (!map.ok()) {
      std::fprintf(stderr, "routing_bench: skipping %s: %s\n", floor, map.error().message.c_str());
      continue;
    }
    const auto shared = std::make_shared<const dispatch::engine::WarehouseMap>(std::move(map).value());
    dispatch::engine::RegisterLazyMapBenchmarks(floor, shared);
    dispatch::engine::RegisterHubLabelBenchmarks(floor, shared);
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
