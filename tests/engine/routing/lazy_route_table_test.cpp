#include "engine/routing/lazy_route_table.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <thread>

#include "engine/routing/floyd_route_table.h"
#include "routing_test_util.h"

namespace dispatch::engine {
namespace {

using testing::CostsAgree;
using testing::ExpectReferenceAnswers;
using testing::ExpectValidRoute;
using testing::RandomMap;
using testing::ReferenceCosts;

struct LazyCase {
  unsigned seed;
  int side;
  double penalty;
};

class LazyRouteTableModelTest : public ::testing::TestWithParam<LazyCase> {};

TEST_P(LazyRouteTableModelTest, SameAnswersAsTheDenseTableAndReference) {
  const LazyCase c = GetParam();
  const auto map = RandomMap(c.seed, c.side);
  RouteTableOptions options;
  options.speed = 0.8;
  options.turn_penalty_s = c.penalty;
  const auto dense = FloydRouteTable::Build(map, options).value();
  const auto lazy = LazyRouteTable::Build(map, options).value();
  EXPECT_EQ(lazy->method(), "lazy");
  ExpectReferenceAnswers(*map, *lazy, options.speed, c.penalty, [&](PointId u, PointId v) {
    ASSERT_TRUE(CostsAgree(dense->Cost(u, v), lazy->Cost(u, v)));
  });
  if (::testing::Test::HasFatalFailure()) return;
  EXPECT_EQ(lazy->searches(), map->point_count());  // one search per destination
}

// Weighted (Wang2019's path heat as a table): the routes are the cheapest by weighted drive
// time plus turns (the reference with the weights), and Cost is what driving them takes
// (ExpectValidRoute recomputes it unweighted), never less than the shortest time.
TEST_P(LazyRouteTableModelTest, WeightedRoutesAreTheCheapestWeightedAndCostTheirDriveTime) {
  const LazyCase c = GetParam();
  const auto map = RandomMap(c.seed, c.side);
  RouteTableOptions options;
  options.speed = 0.8;
  options.turn_penalty_s = c.penalty;
  std::mt19937 rng(c.seed);
  std::uniform_real_distribution<double> heat(1.0, 3.0);
  std::vector<double> weight(map->arcs().size());
  for (double& w : weight) w = heat(rng);
  const auto table = LazyRouteTable::BuildWeighted(map, options, weight).value();
  EXPECT_EQ(table->method(), "weighted");
  EXPECT_EQ(table->build_info().method, "weighted");
  int longer = 0;
  const auto n = static_cast<PointId>(map->point_count());
  for (PointId u = 0; u < n; ++u) {
    const std::vector<double> shortest = ReferenceCosts(*map, u, options.speed, c.penalty);
    const std::vector<double> weighted = ReferenceCosts(*map, u, options.speed, c.penalty, &weight);
    for (PointId v = 0; v < n; ++v) {
      const auto vi = static_cast<std::size_t>(v);
      ExpectValidRoute(*map, *table, u, v, options.speed, c.penalty);
      if (::testing::Test::HasFatalFailure()) return;
      ASSERT_EQ(std::isinf(table->Cost(u, v)), std::isinf(shortest[vi])) << u << "->" << v;
      if (std::isinf(shortest[vi]) || u == v) continue;
      const Route r = table->Path(u, v).value();
      double w_sum = 0.0;
      for (std::size_t i = 0; i < r.arcs.size(); ++i) {
        const Arc& a = map->arc(r.arcs[i]);
        w_sum += weight[static_cast<std::size_t>(r.arcs[i])] * a.length /
                 (a.max_speed > 0 ? std::min(options.speed, a.max_speed) : options.speed);
        if (i > 0) w_sum += c.penalty * TurnAngle(*map, r.arcs[i - 1], r.arcs[i]) / (std::numbers::pi / 2);
      }
      ASSERT_NEAR(w_sum, weighted[vi], 1e-9 * std::max(1.0, w_sum)) << u << "->" << v;
      ASSERT_GE(table->Cost(u, v), shortest[vi] - 1e-9 * std::max(1.0, shortest[vi])) << u << "->" << v;
      if (table->Cost(u, v) > shortest[vi] + 1e-6) ++longer;
    }
  }
  EXPECT_GT(longer, 0);  // the weights send some routes round
}

INSTANTIATE_TEST_SUITE_P(RandomMaps, LazyRouteTableModelTest,
                         ::testing::Values(LazyCase{21, 6, 0.0}, LazyCase{22, 10, 0.0},
                                           LazyCase{23, 7, 1.0}, LazyCase{24, 9, 4.0}),
                         [](const ::testing::TestParamInfo<LazyCase>& info) {
                           return "seed" + std::to_string(info.param.seed) +
                                  (info.param.penalty > 0 ? "_turns" : "");
                         });

TEST(LazyRouteTableTest, CacheIsBoundedAndEvictsLeastRecentlyUsed) {
  const auto map = RandomMap(31, 8);
  RouteTableOptions options;
  const std::size_t entry_bytes = map->point_count() * 12;
  options.lazy_cache_bytes = 3 * entry_bytes;
  const auto lazy = LazyRouteTable::Build(map, options).value();
  const auto dense = FloydRouteTable::Build(map, options).value();
  lazy->Cost(0, 1);
  lazy->Cost(0, 2);
  lazy->Cost(0, 3);
  EXPECT_EQ(lazy->cached_destinations(), 3u);
  EXPECT_EQ(lazy->searches(), 3u);
  lazy->Cost(5, 1);  // hit: 1 becomes the most recent
  EXPECT_EQ(lazy->searches(), 3u);
  lazy->Cost(0, 4);  // evicts 2, the least recently used
  EXPECT_EQ(lazy->cached_destinations(), 3u);
  lazy->Cost(7, 1);
  lazy->Cost(7, 3);
  EXPECT_EQ(lazy->searches(), 4u);
  lazy->Cost(7, 2);
  EXPECT_EQ(lazy->searches(), 5u);
  // Still right after churning through every destination.
  const auto n = static_cast<PointId>(map->point_count());
  for (PointId v = 0; v < n; ++v) {
    for (PointId u = 0; u < n; u += 3) ASSERT_TRUE(CostsAgree(dense->Cost(u, v), lazy->Cost(u, v)));
  }
  EXPECT_LE(lazy->cached_destinations(), 3u);
  // A bound below one entry still keeps the newest.
  options.lazy_cache_bytes = 1;
  const auto tiny = LazyRouteTable::Build(map, options).value();
  EXPECT_TRUE(CostsAgree(dense->Cost(0, 9), tiny->Cost(0, 9)));
  EXPECT_EQ(tiny->cached_destinations(), 1u);
}

// CostsTo(to)[p] is Cost(p, to) for every point (read in place by the traffic controller's
// bounded searches); tables without such an array say so with nullptr.
TEST(LazyRouteTableTest, CostsToHoldsEveryPointsCost) {
  const auto map = RandomMap(35, 8);
  const auto lazy = LazyRouteTable::Build(map, {}).value();
  const auto n = static_cast<PointId>(map->point_count());
  for (PointId to : {PointId{0}, PointId{5}, static_cast<PointId>(n - 1)}) {
    const double* costs = lazy->CostsTo(to);
    ASSERT_NE(costs, nullptr);
    for (PointId p = 0; p < n; ++p) {
      const double c = lazy->Cost(p, to);
      const double in_place = costs[static_cast<std::size_t>(p)];
      EXPECT_TRUE(in_place == c || (std::isinf(c) && std::isinf(in_place))) << p << "->" << to;
    }
  }
  EXPECT_EQ(lazy->CostsTo(-1), nullptr);
  EXPECT_EQ(lazy->CostsTo(n), nullptr);
  RouteTableOptions turns;
  turns.turn_penalty_s = 2.0;
  EXPECT_EQ(LazyRouteTable::Build(map, turns).value()->CostsTo(0), nullptr);
  EXPECT_EQ(FloydRouteTable::Build(map, {}).value()->CostsTo(0), nullptr);
}

TEST(LazyRouteTableTest, PrepareRunsTheSearchAheadOfTheQueries) {
  const auto map = RandomMap(33, 8);
  const auto lazy = LazyRouteTable::Build(map, {}).value();
  const auto dense = FloydRouteTable::Build(map, {}).value();
  lazy->Prepare(3);
  EXPECT_EQ(lazy->searches(), 1u);
  EXPECT_EQ(lazy->cached_destinations(), 1u);
  EXPECT_TRUE(CostsAgree(dense->Cost(0, 3), lazy->Cost(0, 3)));
  EXPECT_EQ(lazy->NextHop(0, 3) == kNoPoint, dense->NextHop(0, 3) == kNoPoint);
  EXPECT_EQ(lazy->searches(), 1u);  // the queries found it
  lazy->Prepare(-1);
  lazy->Prepare(static_cast<PointId>(map->point_count()));
  EXPECT_EQ(lazy->searches(), 1u);  // unknown ids: nothing to prepare
  dense->Prepare(3);                // dense tables have nothing to do
}

TEST(LazyRouteTableTest, EachTableAnswersFromItsOwnEntries) {
  // A thread keeps its last entry per table: alternating two tables (different floors, the
  // same destination id) must never answer one from the other's search.
  const auto map_a = RandomMap(51, 9);
  const auto map_b = RandomMap(52, 9);
  const auto a = LazyRouteTable::Build(map_a, {}).value();
  const auto b = LazyRouteTable::Build(map_b, {}).value();
  const auto dense_a = FloydRouteTable::Build(map_a, {}).value();
  const auto dense_b = FloydRouteTable::Build(map_b, {}).value();
  const auto n = static_cast<PointId>(std::min(map_a->point_count(), map_b->point_count()));
  int differ = 0;
  for (PointId u = 0; u < n; ++u) {
    ASSERT_TRUE(CostsAgree(dense_a->Cost(u, 0), a->Cost(u, 0)));
    ASSERT_TRUE(CostsAgree(dense_b->Cost(u, 0), b->Cost(u, 0)));
    differ += !CostsAgree(dense_a->Cost(u, 0), dense_b->Cost(u, 0));
  }
  EXPECT_GT(differ, 0);  // the floors differ, so a mix-up would show
  // A table built where a destroyed one was answers from its own search too.
  for (int round = 0; round < 3; ++round) {
    const auto t = LazyRouteTable::Build(round % 2 ? map_a : map_b, {}).value();
    const auto& dense = round % 2 ? dense_a : dense_b;
    for (PointId u = 0; u < n; ++u) ASSERT_TRUE(CostsAgree(dense->Cost(u, 1), t->Cost(u, 1)));
  }
}

TEST(LazyRouteTableTest, ConcurrentQueriesAgreeWithSequentialOnes) {
  const auto map = RandomMap(41, 10);
  RouteTableOptions options;
  options.turn_penalty_s = 1.0;
  options.lazy_cache_bytes = 20 * (map->point_count() + map->arcs().size()) * 12;  // churn
  const auto dense = FloydRouteTable::Build(map, options).value();
  const auto lazy = LazyRouteTable::Build(map, options).value();
  const auto n = static_cast<PointId>(map->point_count());
  std::vector<int> mismatches(2, 0);
  auto work = [&](int id) {
    for (int round = 0; round < 3; ++round) {
      for (PointId v = 0; v < n; ++v) {
        const PointId to = (v * 7 + id * 13 + round) % n;
        for (PointId u = 0; u < n; u += 5) {
          if (!CostsAgree(dense->Cost(u, to), lazy->Cost(u, to))) ++mismatches[id];
          const auto path = lazy->Path(u, to);
          if (path.ok() && !CostsAgree(path.value().cost, lazy->Cost(u, to))) ++mismatches[id];
        }
      }
    }
  };
  {
    std::jthread other(work, 1);
    work(0);
  }
  EXPECT_EQ(mismatches[0], 0);
  EXPECT_EQ(mismatches[1], 0);
}

TEST(LazyRouteTableTest, ErrorsNameBothPoints) {
  const auto map = RandomMap(51, 5);
  const auto lazy = LazyRouteTable::Build(map, {}).value();
  const auto unknown = lazy->Path(0, 1000);
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.error().code, ErrorCode::kNotFound);
  EXPECT_NE(unknown.error().message.find("'" + map->point(0).name + "'"), std::string::npos);
  EXPECT_NE(unknown.error().message.find("1000"), std::string::npos);
  EXPECT_TRUE(std::isinf(lazy->Cost(0, -3)));
  EXPECT_EQ(lazy->NextHop(0, -3), kNoPoint);
  EXPECT_EQ(lazy->searches(), 0u);
  EXPECT_EQ(LazyRouteTable::Build(nullptr, {}).error().code, ErrorCode::kInvalidArgument);
}

TEST(LazyRouteTableTest, WeightsAreOnePerArcFiniteAndAtLeastOne) {
  const auto map = RandomMap(5, 4);
  const RouteTableOptions options;
  const std::size_t arcs = map->arcs().size();
  auto error = [&](std::vector<double> w) { return LazyRouteTable::BuildWeighted(map, options, w).error().message; };
  EXPECT_NE(error(std::vector<double>(arcs + 1, 1.0)).find("arc weights for"), std::string::npos);
  std::vector<double> w(arcs, 1.0);
  w[2] = 0.5;
  EXPECT_NE(error(w).find("arc 2 has weight"), std::string::npos);
  w[2] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(error(w).find("arc 2"), std::string::npos);
  // All weights 1: the plain table's costs.
  const auto plain = LazyRouteTable::Build(map, options).value();
  const auto ones = LazyRouteTable::BuildWeighted(map, options, std::vector<double>(arcs, 1.0)).value();
  for (PointId u = 0; u < static_cast<PointId>(map->point_count()); ++u) {
    for (PointId v = 0; v < static_cast<PointId>(map->point_count()); ++v) {
      EXPECT_DOUBLE_EQ(plain->Cost(u, v), ones->Cost(u, v)) << u << "->" << v;
    }
  }
}

}  // namespace
}  // namespace dispatch::engine
