#include "engine/routing/floyd.h"

#include <gtest/gtest.h>

#include "engine/routing/dijkstra.h"
#include "routing_test_util.h"

namespace dispatch::engine {
namespace {

using testing::CostsAgree;

// Every all-pairs table must agree with per-source Dijkstra on every distance, and every
// next-pointer walk must be a path of existing arcs whose summed cost is that distance.
void ExpectMatchesDijkstra(const CostGraph& g, const AllPairsTable& t, const std::string& what) {
  ASSERT_EQ(t.n, g.vertex_count());
  const auto n = static_cast<VertexId>(g.vertex_count());
  for (VertexId s = 0; s < n; ++s) {
    const ShortestPathTree ref = Dijkstra(g, s);
    for (VertexId v = 0; v < n; ++v) {
      const double expected = ref.dist[static_cast<std::size_t>(v)];
      ASSERT_TRUE(CostsAgree(expected, t.Dist(s, v)))
          << what << ": " << s << " -> " << v << " expected " << expected << " got " << t.Dist(s, v);
      const std::vector<VertexId> path = WalkNext(t, s, v);
      if (std::isinf(expected)) {
        ASSERT_TRUE(path.empty()) << what;
        ASSERT_EQ(t.Next(s, v), kNoVertex) << what;
        continue;
      }
      ASSERT_FALSE(path.empty()) << what << ": no walk " << s << " -> " << v;
      ASSERT_EQ(path.front(), s);
      ASSERT_EQ(path.back(), v);
      double sum = 0;
      for (std::size_t i = 0; i + 1 < path.size(); ++i) {
        const std::int32_t id = g.CheapestArc(path[i], path[i + 1]);
        ASSERT_GE(id, 0) << what << ": no arc " << path[i] << " -> " << path[i + 1];
        sum += g.arc(id).cost;
      }
      ASSERT_TRUE(CostsAgree(expected, sum)) << what << ": walk sums to " << sum;
    }
  }
}

struct Case {
  unsigned seed;
  int n;
  double density;
};

class FloydModelTest : public ::testing::TestWithParam<Case> {};

TEST_P(FloydModelTest, EveryImplementationAgreesWithDijkstra) {
  const Case c = GetParam();
  const CostGraph g = testing::RandomCostGraph(c.seed, c.n, c.density);
  ExpectMatchesDijkstra(g, FloydTextbook(g).value(), "textbook");
  ExpectMatchesDijkstra(g, FloydBlocked(g, 1).value(), "blocked/1");
  ExpectMatchesDijkstra(g, FloydBlocked(g, 2).value(), "blocked/2");
  ExpectMatchesDijkstra(g, FloydBlocked(g, 3).value(), "blocked/3");
  ExpectMatchesDijkstra(g, AllPairsDijkstra(g, 1).value(), "dijkstra/1");
  ExpectMatchesDijkstra(g, AllPairsDijkstra(g, 2).value(), "dijkstra/2");
}

// Sizes around the 64-wide tile edges; sparse and dense graphs.
INSTANTIATE_TEST_SUITE_P(RandomGraphs, FloydModelTest,
                         ::testing::Values(Case{1, 1, 1.0}, Case{2, 2, 2.0}, Case{3, 17, 1.5},
                                           Case{4, 63, 2.5}, Case{5, 64, 3.0}, Case{6, 65, 1.2},
                                           Case{7, 130, 2.0}, Case{8, 200, 3.0},
                                           Case{9, 150, 12.0}, Case{10, 257, 1.0}),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           return "seed" + std::to_string(info.param.seed) + "_n" +
                                  std::to_string(info.param.n);
                         });

TEST(FloydTest, EmptyGraph) {
  const CostGraph g = CostGraph::Build(0, {}).value();
  EXPECT_EQ(FloydTextbook(g).value().n, 0u);
  EXPECT_EQ(FloydBlocked(g, 2).value().n, 0u);
  EXPECT_EQ(AllPairsDijkstra(g, 2).value().n, 0u);
}

TEST(FloydTest, ZeroCostCycleKeepsWalksFinite) {
  // 0 <-> 1 <-> 2 all free, 2 -> 3 costs 1.
  const CostGraph g =
      CostGraph::Build(4, {{0, 1, 0}, {1, 0, 0}, {1, 2, 0}, {2, 1, 0}, {2, 0, 0}, {2, 3, 1}})
          .value();
  ExpectMatchesDijkstra(g, FloydTextbook(g).value(), "textbook");
  ExpectMatchesDijkstra(g, FloydBlocked(g, 2).value(), "blocked");
  ExpectMatchesDijkstra(g, AllPairsDijkstra(g, 2).value(), "dijkstra");
}

TEST(FloydTest, ManyEqualCostTiesAndZeroCostArcs) {
  // Costs 0 or 1 only: nearly every pair has many shortest paths and zero-cost cycles abound.
  std::mt19937 rng(99);
  for (int n : {40, 150, 300}) {
    std::vector<CostArc> arcs;
    for (int i = 0; i < 3 * n; ++i) {
      arcs.push_back({static_cast<VertexId>(rng() % n), static_cast<VertexId>(rng() % n),
                      static_cast<double>(rng() % 2)});
    }
    const CostGraph g = CostGraph::Build(static_cast<std::size_t>(n), std::move(arcs)).value();
    ExpectMatchesDijkstra(g, FloydTextbook(g).value(), "textbook");
    ExpectMatchesDijkstra(g, FloydBlocked(g, 2).value(), "blocked/2");
    ExpectMatchesDijkstra(g, AllPairsDijkstra(g, 2).value(), "dijkstra/2");
  }
}

TEST(FloydTest, LargerSparseGraphAllImplementationsAgree) {
  const CostGraph g = testing::RandomCostGraph(12, 700, 2.5);
  ExpectMatchesDijkstra(g, FloydBlocked(g, 2).value(), "blocked/2");
  ExpectMatchesDijkstra(g, AllPairsDijkstra(g, 2).value(), "dijkstra/2");
}

TEST(FloydTest, CancelledBuildsReturnAnError) {
  const CostGraph g = testing::RandomCostGraph(11, 300, 2.0);
  for (int threads : {1, 2}) {
    int calls = 0;
    auto cancel_third = [&calls] { return ++calls >= 3; };
    auto blocked = FloydBlocked(g, threads, cancel_third);
    ASSERT_FALSE(blocked.ok());
    EXPECT_EQ(blocked.error().code, ErrorCode::kFailedPrecondition);
    EXPECT_EQ(calls, 3);
    calls = 0;
    auto dijkstra = AllPairsDijkstra(g, threads, cancel_third);
    ASSERT_FALSE(dijkstra.ok());
    EXPECT_EQ(dijkstra.error().code, ErrorCode::kFailedPrecondition);
  }
  int calls = 0;
  auto textbook = FloydTextbook(g, [&calls] { return ++calls >= 3; });
  ASSERT_FALSE(textbook.ok());
  EXPECT_EQ(textbook.error().code, ErrorCode::kFailedPrecondition);
  // A check that never fires changes nothing.
  EXPECT_TRUE(FloydBlocked(g, 2, [] { return false; }).ok());
}

}  // namespace
}  // namespace dispatch::engine
