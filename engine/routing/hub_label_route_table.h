// HubLabelRouteTable: a RouteTable for large floors that answers any pair without a search per
// destination (issue 19 §1): hub labels (hub_labels.h) over the map's cost graph. Cost is a
// merge of two labels (~1 us on the LoRR floors); NextHop reads the first arc kept with the
// cheapest hub's entry (one label); Path repeats it. Memory is the labels' (build_info
// table_bytes), whatever the destinations asked; the build is a one-off preprocessing
// (routing_bench and the README give its time on the LoRR floors). NextHop and Path read the
// destination's label spread over arrays by hub, kept per thread (12 bytes per searched
// vertex per thread that asks); so does Cost from its third call in a row towards one
// destination.
//
// With turn penalties the labels are built over the arc-expanded graph plus one sink vertex
// per point, joined from each of its arrival vertices at cost 0, so that Cost(u, v) is one
// query to v's sink. Answers equal LazyRouteTable's costs up to rounding; among routes of equal
// cost NextHop takes the first arc towards the cheapest hub of lowest rank (HubLabels::FirstHop),
// so a walk of NextHops need not follow one Path (each is a cheapest route). Path needs a
// graph without cycles of arcs that cost nothing (a map's arcs all have a length). Immutable
// after Build: safe for concurrent const calls.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "engine/routing/cost_graph.h"
#include "engine/routing/hub_labels.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine {

class HubLabelRouteTable final : public RouteTable {
 public:
  // `cancelled` is polled during the build (kFailedPrecondition when it says stop).
  static Result<std::unique_ptr<HubLabelRouteTable>> Build(std::shared_ptr<const WarehouseMap> map,
                                                           const RouteTableOptions& options,
                                                           const CancelCheck& cancelled = {});

  std::size_t point_count() const override { return graph_.point_count; }
  double Cost(PointId from, PointId to) const override;
  PointId NextHop(PointId from, PointId to) const override;
  Result<Route> Path(PointId from, PointId to) const override;
  std::string_view method() const override { return "hub_labels"; }
  RouteTableBuildInfo build_info() const override;
  const HubLabelStats& label_stats() const { return labels_.stats(); }

 private:
  HubLabelRouteTable() = default;
  bool Known(PointId p) const { return p >= 0 && static_cast<std::size_t>(p) < graph_.point_count; }
  // The vertex a route to point p ends at: p, or p's sink with turn penalties.
  VertexId Target(PointId p) const;
  // `target`'s backward label spread by hub (HubLabels::Spread), kept per thread for the
  // last target it asked of this table: a walk, or a run of NextHop calls towards one
  // destination, spreads it once. Valid until this thread's next call with another target.
  const HubSpread& SpreadTo(VertexId target) const;

  std::shared_ptr<const WarehouseMap> map_;
  MapCostGraph graph_;
  // The graph the labels cover: graph_.graph, or with turn penalties with_sinks_ (it plus the
  // sinks and their arcs).
  const CostGraph& search() const { return graph_.expanded ? with_sinks_ : graph_.graph; }
  CostGraph with_sinks_;
  HubLabels labels_;
  std::uint64_t id_ = 0;  // unique per table ever built (the per-thread spread's key)
};

}  // namespace dispatch::engine
