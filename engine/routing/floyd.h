// Dense all-pairs shortest paths on a CostGraph: Floyd-Warshall (Chu2024 §3.1, steps 1-4).
//
// AllPairsTable is the seed's distance matrix D and path matrix P, row-major n x n. We keep P
// as a successor (next-hop) matrix instead of the seed's predecessor matrix: next(i, j) is the
// vertex after i on a shortest i -> j path (j for a direct arc, i for i == j, kNoVertex when j
// is unreachable), so a next hop is O(1) and a path is a walk of next pointers.
// Distances are float (+inf when unreachable): relative error <= ~1e-6 per relaxation chain,
// compared with double Dijkstra. Tables are plain values; safe to share once built.
//
// The builders poll `cancelled` only on the calling thread and return kFailedPrecondition
// ("cancelled") when it returns true.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "engine/common/result.h"
#include "engine/routing/cost_graph.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine {

struct AllPairsTable {
  std::size_t n = 0;
  std::vector<float> dist;          // D, n * n
  std::vector<VertexId> next;       // successor matrix, n * n

  float Dist(VertexId i, VertexId j) const { return dist[Index(i, j)]; }
  VertexId Next(VertexId i, VertexId j) const { return next[Index(i, j)]; }
  std::size_t bytes() const { return dist.size() * sizeof(float) + next.size() * sizeof(VertexId); }
  std::size_t Index(VertexId i, VertexId j) const {
    return static_cast<std::size_t>(i) * n + static_cast<std::size_t>(j);
  }
};

// Seed steps 1-2: D from the adjacency (cheapest parallel arc), D(i,i) = 0, P from the arcs.
AllPairsTable InitAllPairsTable(const CostGraph& graph);

// The reference: seed step 3-4 verbatim, one compare-and-update of D and P per (k, i, j),
// nothing skipped. Polls `cancelled` once per k.
Result<AllPairsTable> FloydTextbook(const CostGraph& graph, const CancelCheck& cancelled = {});

// Production Floyd: tiled 3-phase Floyd-Warshall on D (64 x 64 tiles, auto-vectorised
// min-plus row loops), each phase split over `threads` std::threads (the caller is worker 0),
// rows with infinite D(i, k) skipped; polls `cancelled` between k-blocks. The successor matrix
// is then derived from the final D by Bellman's equation, next(i, j) = argmin over out-arcs
// (i, w) of cost + D(w, j), in O(n * m): this keeps the successor select out of the O(n^3)
// loop. A final O(n^2) pass checks that every destination's successor pointers form a tree
// and recomputes any column that has a cycle (possible around zero-cost cycles) with an exact
// reverse Dijkstra. Same distances as FloydTextbook; paths may differ between equal-cost ties.
Result<AllPairsTable> FloydBlocked(const CostGraph& graph, int threads,
                                   const CancelCheck& cancelled = {});

// Vertex sequence from -> to walking next pointers; empty when unreachable. The walk is
// bounded by n steps (an empty result then too, which never happens for a consistent table).
std::vector<VertexId> WalkNext(const AllPairsTable& table, VertexId from, VertexId to);

}  // namespace dispatch::engine
