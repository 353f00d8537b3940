#include "engine/routing/hub_label_route_table.h"

#include <algorithm>
#include <atomic>
#include <utility>

#include "engine/common/numbers.h"

namespace dispatch::engine {
namespace {

std::atomic<std::uint64_t> next_label_table_id{1};

struct SpreadCache {
  std::uint64_t table = 0;
  VertexId target = kNoVertex;
  HubSpread by_hub;
  // Cost's last target, of table `asked_table`, and how many calls in a row asked it again.
  std::uint64_t asked_table = 0;
  VertexId asked = kNoVertex;
  int asked_again = 0;
};

SpreadCache& ThreadSpread() {
  thread_local SpreadCache cache;
  return cache;
}

}  // namespace

Result<std::unique_ptr<HubLabelRouteTable>> HubLabelRouteTable::Build(std::shared_ptr<const WarehouseMap> map,
                                                                      const RouteTableOptions& options,
                                                                      const CancelCheck& cancelled) {
  if (!map) return InvalidArgument("HubLabelRouteTable: null map");
  auto graph = BuildMapCostGraph(*map, options);
  if (!graph.ok()) return graph.error();
  std::unique_ptr<HubLabelRouteTable> t(new HubLabelRouteTable());
  t->map_ = std::move(map);
  t->graph_ = std::move(graph).value();
  if (t->graph_.expanded) {
    // Sink of point p: vertex V + p, entered at cost 0 from every arrival vertex P + e of p.
    const std::size_t v = t->graph_.graph.vertex_count();
    std::vector<CostArc> arcs = t->graph_.graph.arcs();
    const std::size_t p = t->graph_.point_count;
    for (ArcId e = 0; static_cast<std::size_t>(e) < t->map_->arcs().size(); ++e) {
      arcs.push_back({static_cast<VertexId>(p + static_cast<std::size_t>(e)),
                      static_cast<VertexId>(v + static_cast<std::size_t>(t->map_->arc(e).to)), 0.0});
    }
    auto search = CostGraph::Build(v + p, std::move(arcs));
    if (!search.ok()) return search.error();
    t->with_sinks_ = std::move(search).value();
  }
  auto labels = HubLabels::Build(t->search(), {}, cancelled);
  if (!labels.ok()) return labels.error();
  t->labels_ = std::move(labels).value();
  t->id_ = next_label_table_id.fetch_add(1);
  return t;
}

VertexId HubLabelRouteTable::Target(PointId p) const {
  return graph_.expanded ? static_cast<VertexId>(graph_.graph.vertex_count() + static_cast<std::size_t>(p)) : p;
}

const HubSpread& HubLabelRouteTable::SpreadTo(VertexId target) const {
  SpreadCache& c = ThreadSpread();
  if (c.table == id_ && c.target == target) return c.by_hub;
  if (c.table == id_) {
    labels_.Unspread(c.target, c.by_hub);
  } else {
    c.by_hub.Reset(labels_.vertex_count());
  }
  labels_.Spread(target, c.by_hub);
  c.table = id_;
  c.target = target;
  return c.by_hub;
}

double HubLabelRouteTable::Cost(PointId from, PointId to) const {
  if (!Known(from) || !Known(to)) return kInf;
  if (from == to) return 0.0;
  const VertexId target = Target(to);
  SpreadCache& c = ThreadSpread();
  if (c.table == id_ && c.target == target) return labels_.DistanceVia(from, c.by_hub);
  // The third call in a row towards one target spreads it (a bid's robots, a search's
  // heuristic): from then on one label is read per call instead of two merged.
  if (c.asked_table == id_ && c.asked == target) {
    if (++c.asked_again >= 2) return labels_.DistanceVia(from, SpreadTo(target));
  } else {
    c.asked_table = id_;
    c.asked = target;
    c.asked_again = 0;
  }
  return labels_.Distance(from, target);
}

PointId HubLabelRouteTable::NextHop(PointId from, PointId to) const {
  if (!Known(from) || !Known(to) || from == to) return kNoPoint;
  const HubLabels::FirstHop hop = labels_.FirstVia(from, SpreadTo(Target(to)));
  if (hop.arc < 0) return kNoPoint;
  return map_->arc(graph_.map_arc[static_cast<std::size_t>(hop.arc)]).to;
}

Result<Route> HubLabelRouteTable::Path(PointId from, PointId to) const {
  if (!Known(from) || !Known(to)) return NoRouteError(*map_, from, to);
  if (from == to) return Route{{from}, {}, 0.0, 0.0};
  const VertexId sink = Target(to);
  const HubSpread& target = SpreadTo(sink);
  std::vector<VertexId> path{from};
  // Each hop leaves on a cheapest route; the sink (turn penalties) is not part of the route.
  for (VertexId v = from; v != to;) {
    const HubLabels::FirstHop hop = labels_.FirstVia(v, target);
    if (hop.cost == kInf && v == from) return NoRouteError(*map_, from, to);
    if (hop.arc < 0 || path.size() > search().vertex_count()) {
      return Error{ErrorCode::kFailedPrecondition, "hub labels: no cheapest arc out of vertex " + std::to_string(v) +
                                                       " towards point " + std::to_string(to)};
    }
    const CostArc& a = search().arc(hop.arc);
    if (a.to == sink && graph_.expanded) break;
    v = a.to;
    path.push_back(v);
  }
  return RouteFromVertexPath(*map_, graph_, path);
}

RouteTableBuildInfo HubLabelRouteTable::build_info() const {
  return {std::string(method()), graph_.point_count, graph_.graph.vertex_count(), graph_.graph.arc_count(),
          graph_.expanded, labels_.stats().bytes, graph_.speed};
}

}  // namespace dispatch::engine
