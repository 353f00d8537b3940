// CostGraph: a generic directed graph with non-negative arc costs in CSR form, and
// BuildMapCostGraph, the travel-time graph of a WarehouseMap that every RouteTable searches.
//
// CostGraph invariants: vertices are 0..vertex_count()-1; arc ids are positions in the arc list
// given to Build and are kept; every arc joins existing vertices and has a finite cost >= 0
// (zero-cost, parallel arcs and self-loops are allowed). Immutable once built: safe to share
// between threads for reading.
//
// MapCostGraph: without turn penalty, vertex p is map point p and graph arc i is map arc i.
// With turn penalty it is the exact arc-expanded graph: vertex p < P is "at point p, no
// heading yet", vertex P + a is "arrived at arc a's head via arc a"; p -> P+a costs cost(a) for
// every out-arc a of p, and P+a -> P+b costs cost(b) + penalty(angle(a, b)) when a ends where b
// starts (Wang2019 eq. (3): turning time t_c, here turn_penalty_s per 90 degrees, a U-turn 2x).
// The distance from point u to point v is min(0 if u == v, min over in-arcs e of v of
// D[u][P+e]).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "engine/common/result.h"
#include "engine/map/warehouse_map.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine {

using VertexId = std::int32_t;
inline constexpr VertexId kNoVertex = -1;

struct CostArc {
  VertexId from = kNoVertex;
  VertexId to = kNoVertex;
  double cost = 0.0;
};

class CostGraph {
 public:
  CostGraph() = default;
  // kInvalidArgument naming the arc when an end is out of range or a cost is negative/NaN/inf.
  static Result<CostGraph> Build(std::size_t vertex_count, std::vector<CostArc> arcs);

  std::size_t vertex_count() const { return vertex_count_; }
  std::size_t arc_count() const { return arcs_.size(); }
  const std::vector<CostArc>& arcs() const { return arcs_; }
  const CostArc& arc(std::int32_t id) const { return arcs_[static_cast<std::size_t>(id)]; }
  // Ids of the arcs leaving / entering v.
  std::span<const std::int32_t> out_arcs(VertexId v) const {
    const auto i = static_cast<std::size_t>(v);
    return {out_ids_.data() + out_begin_[i], out_ids_.data() + out_begin_[i + 1]};
  }
  std::span<const std::int32_t> in_arcs(VertexId v) const {
    const auto i = static_cast<std::size_t>(v);
    return {in_ids_.data() + in_begin_[i], in_ids_.data() + in_begin_[i + 1]};
  }
  // The cheapest arc from -> to (lowest cost, then lowest id); -1 if there is none.
  std::int32_t CheapestArc(VertexId from, VertexId to) const;
  // The cost every arc has, when all arcs cost the same and more than 0 (a grid floor driven
  // at one speed); 0 otherwise. Searches then go level by level (dijkstra.h).
  double uniform_cost() const { return uniform_cost_; }

 private:
  std::size_t vertex_count_ = 0;
  double uniform_cost_ = 0.0;
  std::vector<CostArc> arcs_;
  std::vector<std::size_t> out_begin_, in_begin_;  // vertex_count + 1 offsets
  std::vector<std::int32_t> out_ids_, in_ids_;
};

struct MapCostGraph {
  CostGraph graph;
  std::size_t point_count = 0;
  bool expanded = false;        // turn penalty: the arc-expanded graph described above
  double speed = 0.0;           // the cruise speed of its arc costs
  std::vector<ArcId> map_arc;   // per graph arc: the map arc it drives along

  bool IsPointVertex(VertexId v) const { return static_cast<std::size_t>(v) < point_count; }
  // Vertices at which a route to point p may end: p, plus P+e for each in-arc e when expanded.
  std::vector<VertexId> TargetVertices(const WarehouseMap& map, PointId p) const;
};

// Turn angle in radians [0, pi] between arc `in` and arc `out` (chord headings); 0 when a
// heading is undefined (coincident end points).
double TurnAngle(const WarehouseMap& map, ArcId in, ArcId out);

// Arc cost = length / min(speed, max_speed if > 0). kInvalidArgument for speed <= 0,
// a negative or non-finite turn penalty, or a graph too large for 32-bit vertex ids.
Result<MapCostGraph> BuildMapCostGraph(const WarehouseMap& map, const RouteTableOptions& options);

// The Route for a vertex path of `g` that starts at a point vertex (for each hop the cheapest
// graph arc is taken). `path` must be non-empty and consecutive.
Route RouteFromVertexPath(const WarehouseMap& map, const MapCostGraph& g,
                          std::span<const VertexId> path);

}  // namespace dispatch::engine
