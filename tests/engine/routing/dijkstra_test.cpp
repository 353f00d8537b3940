// Dijkstra's two search loops: on graphs whose arcs all cost the same the searches go level by
// level (dijkstra.h); they must build the very trees the heap builds (same distances, same
// first arcs, same settle order), ties included.
#include "engine/routing/dijkstra.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace dispatch::engine {
namespace {

// Random arcs of cost c between n vertices (parallel arcs, self-loops and many equal-cost
// ties), plus - when `heap` - two extra vertices joined by one dearer arc: the same reachable
// graph with a non-uniform cost, which the heap searches.
CostGraph Uniform(unsigned seed, int n, int m, double c, bool heap) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> pick(0, n - 1);
  std::vector<CostArc> arcs;
  for (int i = 0; i < m; ++i) arcs.push_back({pick(rng), pick(rng), c});
  if (heap) arcs.push_back({n, n + 1, 2.5 * c});
  return CostGraph::Build(static_cast<std::size_t>(n + (heap ? 2 : 0)), std::move(arcs)).value();
}

void ExpectSameTree(const ShortestPathTree& levels, const ShortestPathTree& heap, int n) {
  for (int v = 0; v < n; ++v) {
    const auto i = static_cast<std::size_t>(v);
    ASSERT_EQ(levels.dist[i], heap.dist[i]) << "vertex " << v;
    ASSERT_EQ(levels.via[i], heap.via[i]) << "vertex " << v;
  }
  EXPECT_EQ(levels.order, heap.order);
}

TEST(DijkstraTest, UniformCostGraphsAreSearchedByLevelWithTheHeapsTrees) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const int n = 60 + static_cast<int>(seed) * 7;
    const double c = seed % 2 ? 1.0 : 0.8;  // 0.8: sums that are not exact in binary
    const CostGraph uniform = Uniform(seed, n, 3 * n, c, false);
    const CostGraph heap = Uniform(seed, n, 3 * n, c, true);
    ASSERT_EQ(uniform.uniform_cost(), c);
    ASSERT_EQ(heap.uniform_cost(), 0.0);
    SCOPED_TRACE("seed " + std::to_string(seed));
    for (VertexId s : {0, 1, n / 2, n - 1}) {
      ExpectSameTree(Dijkstra(uniform, s), Dijkstra(heap, s), n);
    }
    const std::vector<VertexId> targets = {n - 1, 3, n / 3, 3};  // a repeated target too
    const ShortestPathTree a = ReverseDijkstra(uniform, targets);
    const ShortestPathTree b = ReverseDijkstra(heap, targets);
    for (int v = 0; v < n; ++v) {
      ASSERT_EQ(a.dist[static_cast<std::size_t>(v)], b.dist[static_cast<std::size_t>(v)]);
      ASSERT_EQ(a.via[static_cast<std::size_t>(v)], b.via[static_cast<std::size_t>(v)]);
    }
  }
}

TEST(DijkstraTest, UniformCostNeedsOnePositiveCostOnEveryArc) {
  EXPECT_EQ(CostGraph::Build(3, {{0, 1, 2.0}, {1, 2, 2.0}}).value().uniform_cost(), 2.0);
  EXPECT_EQ(CostGraph::Build(3, {{0, 1, 2.0}, {1, 2, 2.5}}).value().uniform_cost(), 0.0);
  EXPECT_EQ(CostGraph::Build(3, {{0, 1, 0.0}, {1, 2, 0.0}}).value().uniform_cost(), 0.0);
  EXPECT_EQ(CostGraph::Build(3, {}).value().uniform_cost(), 0.0);
}

}  // namespace
}  // namespace dispatch::engine
