// Hub labels (issue 19 §1): model tests against Dijkstra on random digraphs (zero-cost,
// parallel and one-way arcs, unreachable pairs) and obstacle grids, distances and first arcs; the route table over them
// against the reference costs and routes of every other table, turn penalties included, and on
// a public LoRR floor against the lazy table.
#include "engine/routing/hub_labels.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "engine/io/map_source.h"
#include "engine/routing/dijkstra.h"
#include "engine/routing/hub_label_route_table.h"
#include "engine/routing/lazy_route_table.h"
#include "routing_test_util.h"

namespace dispatch::engine {
namespace {

using testing::ExpectReferenceAnswers;
using testing::RandomCostGraph;
using testing::RandomMap;

// Every pair: Dijkstra's distance; the first arc (FirstVia over the target's spread label)
// leaves the source and starts a cheapest route.
void ExpectExact(const CostGraph& graph, const HubLabels& labels) {
  const auto n = static_cast<VertexId>(graph.vertex_count());
  std::vector<std::vector<double>> dist;
  for (VertexId s = 0; s < n; ++s) dist.push_back(Dijkstra(graph, s).dist);
  HubSpread spread;
  spread.Reset(graph.vertex_count());
  for (VertexId t = 0; t < n; ++t) {
    labels.Spread(t, spread);
    for (VertexId s = 0; s < n; ++s) {
      const double expected = dist[static_cast<std::size_t>(s)][static_cast<std::size_t>(t)];
      const double got = labels.Distance(s, t);
      const HubLabels::FirstHop first = labels.FirstVia(s, spread);
      ASSERT_EQ(first.cost, got) << s << "->" << t;
      ASSERT_EQ(labels.DistanceVia(s, spread), got) << s << "->" << t;
      if (std::isinf(expected)) {
        ASSERT_TRUE(std::isinf(got)) << s << "->" << t << ": " << got;
        ASSERT_EQ(first.arc, -1) << s << "->" << t;
        continue;
      }
      const double tolerance = 1e-9 * std::max(1.0, expected);
      ASSERT_NEAR(got, expected, tolerance) << s << "->" << t;
      if (s == t) {
        ASSERT_EQ(first.arc, -1);
        continue;
      }
      ASSERT_GE(first.arc, 0) << s << "->" << t;
      const CostArc& a = graph.arc(first.arc);
      ASSERT_EQ(a.from, s) << s << "->" << t;
      ASSERT_NEAR(a.cost + dist[static_cast<std::size_t>(a.to)][static_cast<std::size_t>(t)], expected, tolerance)
          << s << "->" << t << " by arc " << first.arc;
    }
    labels.Unspread(t, spread);
  }
}

// A 4-connected grid, both ways at cost `c`, with a share of blocked cells (LoRR's floors).
CostGraph ObstacleGrid(unsigned seed, int w, int h, double blocked, double c) {
  std::mt19937 rng(seed);
  std::bernoulli_distribution wall(blocked);
  std::vector<bool> free(static_cast<std::size_t>(w * h));
  for (std::size_t i = 0; i < free.size(); ++i) free[i] = !wall(rng);
  std::vector<CostArc> arcs;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const int v = y * w + x;
      if (!free[static_cast<std::size_t>(v)]) continue;
      if (x + 1 < w && free[static_cast<std::size_t>(v + 1)]) {
        arcs.push_back({v, v + 1, c});
        arcs.push_back({v + 1, v, c});
      }
      if (y + 1 < h && free[static_cast<std::size_t>(v + w)]) {
        arcs.push_back({v, v + w, c});
        arcs.push_back({v + w, v, c});
      }
    }
  }
  return CostGraph::Build(static_cast<std::size_t>(w * h), std::move(arcs)).value();
}

TEST(HubLabelsTest, RandomDigraphsGetDijkstrasDistances) {
  for (unsigned seed = 1; seed <= 12; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const int n = static_cast<int>(seed) * 17;
    const CostGraph graph = RandomCostGraph(seed, n, 1.0 + 0.4 * seed);
    const HubLabels labels = HubLabels::Build(graph).value();
    ASSERT_EQ(labels.vertex_count(), graph.vertex_count());
    ExpectExact(graph, labels);
    if (::testing::Test::HasFatalFailure()) return;
  }
}

TEST(HubLabelsTest, ObstacleGridsGetDijkstrasDistances) {
  for (unsigned seed = 1; seed <= 4; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const CostGraph graph = ObstacleGrid(seed, 24 + static_cast<int>(seed), 20, 0.2, seed % 2 ? 1.0 : 0.8);
    const HubLabels labels = HubLabels::Build(graph).value();
    ExpectExact(graph, labels);
    if (::testing::Test::HasFatalFailure()) return;
    EXPECT_GT(labels.stats().label_entries, 0u);
    EXPECT_GT(labels.stats().bytes, 0u);
  }
}

// A witness search that gives up at once adds every shortcut it could need: more arcs, the
// same distances.
TEST(HubLabelsTest, AShortWitnessSearchOnlyAddsShortcuts) {
  const CostGraph graph = ObstacleGrid(7, 20, 16, 0.15, 1.0);
  const HubLabels full = HubLabels::Build(graph).value();
  const HubLabels hasty = HubLabels::Build(graph, {.witness_settle_limit = 1}).value();
  EXPECT_GT(hasty.stats().shortcuts, full.stats().shortcuts);
  ExpectExact(graph, hasty);
}

TEST(HubLabelsTest, UnknownVerticesAreUnreachableAndBadOptionsRefused) {
  const CostGraph graph = RandomCostGraph(3, 30, 2.0);
  const HubLabels labels = HubLabels::Build(graph).value();
  EXPECT_TRUE(std::isinf(labels.Distance(-1, 0)));
  EXPECT_TRUE(std::isinf(labels.Distance(0, 30)));
  EXPECT_EQ(labels.Distance(5, 5), 0.0);
  HubSpread spread;
  spread.Reset(labels.vertex_count());
  labels.Spread(5, spread);
  EXPECT_EQ(labels.FirstVia(5, spread).cost, 0.0);
  EXPECT_EQ(labels.FirstVia(5, spread).arc, -1);
  EXPECT_TRUE(std::isinf(labels.FirstVia(30, spread).cost));
  EXPECT_EQ(labels.FirstVia(-1, spread).arc, -1);
  EXPECT_EQ(HubLabels::Build(graph, {.witness_settle_limit = 0}).error().code, ErrorCode::kInvalidArgument);
  const HubLabels empty = HubLabels::Build(CostGraph::Build(0, {}).value()).value();
  EXPECT_EQ(empty.vertex_count(), 0u);
  EXPECT_TRUE(std::isinf(empty.Distance(0, 0)));
}

TEST(HubLabelsTest, ACancelledBuildStops) {
  const CostGraph graph = ObstacleGrid(5, 40, 40, 0.2, 1.0);
  int polls = 0;
  const auto built = HubLabels::Build(graph, {}, [&polls] { return ++polls > 3; });
  ASSERT_FALSE(built.ok());
  EXPECT_EQ(built.error().code, ErrorCode::kFailedPrecondition);
  EXPECT_EQ(polls, 4);
}

struct TableCase {
  unsigned seed;
  int side;
  double penalty;
};

class HubLabelRouteTableTest : public ::testing::TestWithParam<TableCase> {};

// Every pair: the reference's cost, a NextHop exactly when a route exists, and a valid route of
// that cost (ExpectValidRoute recomputes it from the map, turns included).
TEST_P(HubLabelRouteTableTest, SameAnswersAsTheReference) {
  const TableCase c = GetParam();
  const auto map = RandomMap(c.seed, c.side);
  RouteTableOptions options;
  options.speed = 0.8;
  options.turn_penalty_s = c.penalty;
  options.method = RouteTableMethod::kHubLabels;
  const auto table = MakeRouteTable(map, options).value();
  EXPECT_EQ(table->method(), "hub_labels");
  EXPECT_EQ(table->build_info().turn_expanded, c.penalty > 0);
  EXPECT_GT(table->build_info().table_bytes, 0u);
  ExpectReferenceAnswers(*map, *table, options.speed, c.penalty);
}

INSTANTIATE_TEST_SUITE_P(RandomMaps, HubLabelRouteTableTest,
                         ::testing::Values(TableCase{61, 6, 0.0}, TableCase{62, 10, 0.0},
                                           TableCase{63, 7, 1.0}, TableCase{64, 9, 4.0}),
                         [](const ::testing::TestParamInfo<TableCase>& info) {
                           return "seed" + std::to_string(info.param.seed) +
                                  (info.param.penalty > 0 ? "_turns" : "");
                         });

// The LoRR random floor (32 x 32, 20% blocked): a third of the pairs as the lazy table has
// them, and a next hop on a route of the same cost.
TEST(HubLabelRouteTableTest, LorrRandomFloorAgreesWithTheLazyTable) {
  auto loaded = LoadMapSource(std::string(DISPATCH_SHARED_DIR) +
                              "/benchmarks/lorr2024/example_problems/random.domain/maps/random-32-32-20.map");
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  const auto map = std::make_shared<const WarehouseMap>(std::move(loaded).value());
  RouteTableOptions options;
  options.method = RouteTableMethod::kHubLabels;
  const auto labels = MakeRouteTable(map, options).value();
  const auto lazy = LazyRouteTable::Build(map, options).value();
  const auto n = static_cast<PointId>(map->point_count());
  ASSERT_GT(n, 700);
  for (PointId v = 0; v < n; ++v) {
    for (PointId u = v % 3; u < n; u += 3) {
      const double expected = lazy->Cost(u, v);
      ASSERT_EQ(labels->Cost(u, v), expected) << u << "->" << v;  // whole cells: exact sums
      const PointId hop = labels->NextHop(u, v);
      if (u == v || std::isinf(expected)) {
        ASSERT_EQ(hop, kNoPoint);
        continue;
      }
      ASSERT_NE(hop, kNoPoint) << u << "->" << v;
      ASSERT_NEAR(labels->Cost(u, hop) + labels->Cost(hop, v), expected, 1e-9 * expected)
          << u << "->" << v << " via " << hop;
    }
  }
}

}  // namespace
}  // namespace dispatch::engine
