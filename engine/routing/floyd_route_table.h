// FloydRouteTable: the dense RouteTable (Chu2024 §3.1). Holds D and the successor matrix over
// the searched graph (map points, or points + arcs with a turn penalty), built by blocked
// Floyd (default) or all-pairs Dijkstra. Cost and NextHop are O(1) table reads; Path walks the
// successor matrix. With a turn penalty it also keeps, per point pair, the cheaper arrival
// vertex (point x point float cost + int32 vertex) so Cost stays O(1).
//
// Memory: 8 n^2 bytes for n searched vertices (+ 8 P^2 with turn penalty).
// Immutable after Build: safe for concurrent const calls.
#pragma once

#include <memory>

#include "engine/routing/cost_graph.h"
#include "engine/routing/floyd.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine {

class FloydRouteTable final : public RouteTable {
 public:
  // options.method: kDijkstra builds with AllPairsDijkstra, anything else with FloydBlocked
  // (MakeRouteTable resolves kAuto and kLazy before calling this).
  static Result<std::unique_ptr<FloydRouteTable>> Build(std::shared_ptr<const WarehouseMap> map,
                                                        const RouteTableOptions& options,
                                                        const CancelCheck& cancelled = {});

  std::size_t point_count() const override { return graph_.point_count; }
  double Cost(PointId from, PointId to) const override;
  PointId NextHop(PointId from, PointId to) const override;
  Result<Route> Path(PointId from, PointId to) const override;
  std::string_view method() const override { return method_; }
  RouteTableBuildInfo build_info() const override;

 private:
  FloydRouteTable() = default;
  bool Known(PointId p) const { return p >= 0 && static_cast<std::size_t>(p) < graph_.point_count; }
  // The graph vertex a cheapest from -> to route ends at; kNoVertex when unreachable.
  VertexId Arrival(PointId from, PointId to) const;

  std::shared_ptr<const WarehouseMap> map_;
  MapCostGraph graph_;
  AllPairsTable table_;
  std::string method_;
  // Turn-expanded only, P x P: cheapest cost and arrival vertex per point pair.
  std::vector<float> point_cost_;
  std::vector<VertexId> point_arrival_;
};

}  // namespace dispatch::engine
