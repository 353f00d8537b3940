#include "engine/routing/dijkstra.h"

#include <algorithm>
#include <atomic>
#include <functional>
#include <limits>
#include <queue>
#include <thread>
#include <utility>

#include "engine/common/numbers.h"

namespace dispatch::engine {
namespace {

using HeapItem = std::pair<double, VertexId>;
using MinHeap = std::priority_queue<HeapItem, std::vector<HeapItem>, std::greater<>>;

// Uniform arc cost c: every vertex is first reached at its final distance (level k: k c).
// Levels in vertex order settle vertices in the heap's (dist, vertex) order, and the first
// relaxation of a vertex (strict <) comes from the same arc: the same tree.
ShortestPathTree SearchLevels(const CostGraph& graph, std::span<const VertexId> roots, bool reverse,
                              double c) {
  const std::size_t n = graph.vertex_count();
  ShortestPathTree t;
  t.dist.assign(n, kInf);
  t.via.assign(n, -1);
  std::vector<VertexId> level, next;
  for (VertexId r : roots) {
    if (t.dist[static_cast<std::size_t>(r)] == 0.0) continue;
    t.dist[static_cast<std::size_t>(r)] = 0.0;
    level.push_back(r);
  }
  double d = 0.0;
  while (!level.empty()) {
    std::sort(level.begin(), level.end());
    const double dv = d + c;
    for (const VertexId u : level) {
      if (!reverse) t.order.push_back(u);
      for (std::int32_t id : reverse ? graph.in_arcs(u) : graph.out_arcs(u)) {
        const CostArc& a = graph.arc(id);
        const VertexId v = reverse ? a.from : a.to;
        if (dv < t.dist[static_cast<std::size_t>(v)]) {
          t.dist[static_cast<std::size_t>(v)] = dv;
          t.via[static_cast<std::size_t>(v)] = id;
          next.push_back(v);
        }
      }
    }
    level.swap(next);
    next.clear();
    d = dv;
  }
  return t;
}

// Shared loop: `reverse` searches in-arcs and relaxes the arc's tail.
ShortestPathTree GrowTree(const CostGraph& graph, std::span<const VertexId> roots, bool reverse) {
  if (graph.uniform_cost() > 0.0) return SearchLevels(graph, roots, reverse, graph.uniform_cost());
  const std::size_t n = graph.vertex_count();
  ShortestPathTree t;
  t.dist.assign(n, kInf);
  t.via.assign(n, -1);
  MinHeap heap;
  for (VertexId r : roots) {
    t.dist[static_cast<std::size_t>(r)] = 0.0;
    heap.emplace(0.0, r);
  }
  while (!heap.empty()) {
    const auto [du, u] = heap.top();
    heap.pop();
    if (du > t.dist[static_cast<std::size_t>(u)]) continue;  // stale entry
    if (!reverse) t.order.push_back(u);
    for (std::int32_t id : reverse ? graph.in_arcs(u) : graph.out_arcs(u)) {
      const CostArc& a = graph.arc(id);
      const VertexId v = reverse ? a.from : a.to;
      const double dv = du + a.cost;
      if (dv < t.dist[static_cast<std::size_t>(v)]) {
        t.dist[static_cast<std::size_t>(v)] = dv;
        t.via[static_cast<std::size_t>(v)] = id;
        heap.emplace(dv, v);
      }
    }
  }
  return t;
}

}  // namespace

ShortestPathTree Dijkstra(const CostGraph& graph, VertexId source) {
  const VertexId roots[] = {source};
  return GrowTree(graph, roots, false);
}

ShortestPathTree ReverseDijkstra(const CostGraph& graph, std::span<const VertexId> targets) {
  return GrowTree(graph, targets, true);
}

Result<AllPairsTable> AllPairsDijkstra(const CostGraph& graph, int threads,
                                       const CancelCheck& cancelled) {
  const std::size_t n = graph.vertex_count();
  AllPairsTable t;
  t.n = n;
  t.dist.assign(n * n, std::numeric_limits<float>::infinity());
  t.next.assign(n * n, kNoVertex);
  std::atomic<std::size_t> next_source{0};
  std::atomic<bool> stop{false};
  auto work = [&](bool poll) {
    for (;;) {
      if (poll && cancelled && cancelled()) stop = true;
      if (stop) return;
      const std::size_t s = next_source.fetch_add(1);
      if (s >= n) return;
      const ShortestPathTree tree = Dijkstra(graph, static_cast<VertexId>(s));
      float* row = t.dist.data() + s * n;
      VertexId* hop = t.next.data() + s * n;
      hop[s] = static_cast<VertexId>(s);
      // Settle order puts every tree parent before its children: first hop = child of s.
      for (VertexId v : tree.order) {
        const auto vi = static_cast<std::size_t>(v);
        row[vi] = static_cast<float>(tree.dist[vi]);
        if (vi == s) continue;
        const VertexId parent = graph.arc(tree.via[vi]).from;
        hop[vi] = static_cast<std::size_t>(parent) == s ? v : hop[static_cast<std::size_t>(parent)];
      }
    }
  };
  {
    std::vector<std::jthread> pool;
    for (int w = 1; w < std::clamp(threads, 1, 64); ++w) pool.emplace_back(work, false);
    work(true);
  }
  if (stop) return Error{ErrorCode::kFailedPrecondition, "all-pairs build cancelled"};
  return t;
}

}  // namespace dispatch::engine
