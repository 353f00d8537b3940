// Dijkstra on a CostGraph (binary heap, lazy deletion): single source, reverse (towards a set
// of targets, for the lazy table), and all-pairs into the same AllPairsTable Floyd fills.
//
// Distances are double; exact up to floating-point summation. On a graph whose arcs all cost
// the same (CostGraph::uniform_cost: grid floors) the searches run breadth-first, level by
// level with each level in vertex order: the very same trees (dist, via, settle order) as the
// heap, which pops (dist, vertex) in that order, about three times faster. Pure functions of
// their inputs: safe to call concurrently on a shared graph.
#pragma once

#include <span>
#include <vector>

#include "engine/common/result.h"
#include "engine/routing/cost_graph.h"
#include "engine/routing/floyd.h"

namespace dispatch::engine {

struct ShortestPathTree {
  std::vector<double> dist;       // +inf when unreachable
  // Forward: the arc entering v on the tree. Reverse: the first arc of v's cheapest route to
  // the targets. -1 for the roots and unreachable vertices.
  std::vector<std::int32_t> via;
  // Forward only: vertices in the order they were settled (non-decreasing dist).
  std::vector<VertexId> order;
};

ShortestPathTree Dijkstra(const CostGraph& graph, VertexId source);

// Distances *to* the nearest of `targets` (each at distance 0), searching in-arcs.
ShortestPathTree ReverseDijkstra(const CostGraph& graph, std::span<const VertexId> targets);

// One Dijkstra per source, sources split over `threads` std::threads (the caller is worker
// 0 and polls `cancelled` between its sources). Fills D and the successor matrix like Floyd.
Result<AllPairsTable> AllPairsDijkstra(const CostGraph& graph, int threads,
                                       const CancelCheck& cancelled = {});

}  // namespace dispatch::engine
