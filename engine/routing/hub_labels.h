// HubLabels: exact distances between any two vertices of a CostGraph without a search per
// query (issue 19 §1: a route oracle for floors too large for the dense tables, with memory
// bounded by the labels, not by the destinations asked).
//
// Built in two passes:
//  1. A contraction hierarchy (Geisberger, Sanders, Schultes, Delling 2008): vertices are
//     contracted one by one, cheapest first (edge difference + contracted neighbours + level,
//     kept current by lazy updates); contracting v adds a shortcut u -> w for every pair of
//     its remaining neighbours whose route through v no local witness search beats.
//  2. Hierarchical hub labels (Abraham, Delling, Goldberg, Werneck 2012): top-down, each
//     vertex's forward label is its upward search space, merged from the labels of its upward
//     neighbours, with every entry whose distance is not the true distance pruned (a query of
//     the labels already built finds a shorter one); the same backwards.
// Distance(s, t) is then the minimum over the hubs s's forward and t's backward label share:
// a merge of two arrays sorted by hub, ~100-300 entries each on the LoRR warehouse floors.
// Each entry also keeps the first graph arc of its route (forward: from the vertex towards the
// hub; backward: from the hub towards the vertex), so the first arc of a cheapest route comes
// with the same scan (FirstVia): a route is walked one label scan per arc.
//
// Distances are double sums of the graph's arc costs in another order than Dijkstra's: equal
// up to rounding (relative 1e-12). Immutable once built: safe to query from many threads.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "engine/common/result.h"
#include "engine/routing/cost_graph.h"

namespace dispatch::engine {

struct HubLabelOptions {
  // A witness search stops after settling this many vertices; the shortcut is then added
  // (never wrong, only one more arc).
  int witness_settle_limit = 500;
};

// A backward label spread over arrays by hub (HubLabels::Spread): sized vertex_count(), +infinity
// where the label has no entry.
struct HubSpread {
  std::vector<double> dist;
  std::vector<std::int32_t> arc;  // where dist is finite: the entry's first arc
  void Reset(std::size_t vertex_count) {
    dist.assign(vertex_count, std::numeric_limits<double>::infinity());
    arc.assign(vertex_count, -1);
  }
};

struct HubLabelStats {
  std::size_t shortcuts = 0;         // arcs the hierarchy added
  std::size_t label_entries = 0;     // forward + backward
  std::size_t max_label = 0;         // the largest label's entries
  double contract_seconds = 0.0;
  double label_seconds = 0.0;
  std::size_t bytes = 0;             // the labels' memory
};

class HubLabels {
 public:
  HubLabels() = default;
  // `cancelled` (deadline and cancel flag, plan_limits.h) is polled every 256 vertices; a
  // cancelled build returns kFailedPrecondition.
  static Result<HubLabels> Build(const CostGraph& graph, const HubLabelOptions& options = {},
                                 const CancelCheck& cancelled = {});

  std::size_t vertex_count() const { return fwd_begin_.size(); }
  // The cost of a cheapest route from -> to; 0 when from == to; +infinity when there is none
  // or an id is out of range.
  double Distance(VertexId from, VertexId to) const;
  const HubLabelStats& stats() const { return stats_; }

  // A cheapest route's cost and the graph arc it starts with (of the cheapest hubs, the lowest
  // ranked one's): the arc's cost plus the cost from its head is the route's up to rounding.
  // {0, -1} when from == to; {+infinity, -1} when there is no route or an id is out of range.
  struct FirstHop {
    double cost = std::numeric_limits<double>::infinity();
    std::int32_t arc = -1;
  };

  // Many queries towards one vertex: Spread writes `to`'s backward label into `by_hub` (Reset
  // to vertex_count()), after which DistanceVia(from, by_hub) answers Distance(from, to) and
  // FirstVia(from, by_hub) the FirstHop from -> to by reading from's forward label alone, with
  // no merge; Unspread puts the infinities back.
  // For a walk along a route or a bid's robots towards one goal.
  void Spread(VertexId to, HubSpread& by_hub) const;
  void Unspread(VertexId to, HubSpread& by_hub) const;
  double DistanceVia(VertexId from, const HubSpread& by_hub) const;
  FirstHop FirstVia(VertexId from, const HubSpread& by_hub) const;

 private:
  // All labels side by side; vertex v's are [begin[v], end[v]) (stored in the order they were
  // built), entries sorted by hub (the hub's rank: 0 = contracted first).
  std::vector<std::uint64_t> fwd_begin_, fwd_end_, bwd_begin_, bwd_end_;
  std::vector<std::int32_t> fwd_hub_, bwd_hub_;
  std::vector<double> fwd_dist_, bwd_dist_;
  std::vector<std::int32_t> fwd_arc_, bwd_arc_;  // per entry: its first graph arc (-1: the own entry)
  HubLabelStats stats_;
  friend class HubLabelBuilder;
};

}  // namespace dispatch::engine
