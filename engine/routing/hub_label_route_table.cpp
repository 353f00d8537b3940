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
  std::vector<double> by_hub;
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

const std::vector<double>& HubLabelRouteTable::SpreadTo(VertexId target) const {
  SpreadCache& c = ThreadSpread();
  if (c.table == id_ && c.target == target) return c.by_hub;
  if (c.table == id_) {
    labels_.Unspread(c.target, c.by_hub);
  } else {
    c.by_hub.assign(labels_.vertex_count(), kInf);
  }
  labels_.Spread(target, c.by_hub);
  c.table = id_;
  c.target = target;
  return c.by_hub;
}

double HubLabelRouteTable::Cost(PointId from, PointId to) const {
  if (!Known(from) || !Known(to)) return kInf;
  if (from == to) return 0.0;
  const SpreadCache& c = ThreadSpread();
  if (c.table == id_ && c.target == Target(to)) return labels_.DistanceVia(from, c.by_hub);
  return labels_.Distance(from, Target(to));
}

std::int32_t HubLabelRouteTable::BestArc(VertexId v, const std::vector<double>& target, double left) const {
  // An arc is on a cheapest route when its cost plus what is left from its head is `left`;
  // of those, the one whose head is nearest the target (so a walk never goes round a loop of
  // arcs that cost nothing), then the lowest id.
  const double slack = 1e-9 * std::max(1.0, left);
  std::int32_t best = -1;
  double best_rest = kInf;
  const CostGraph& graph = search();
  for (std::int32_t id : graph.out_arcs(v)) {
    const CostArc& a = graph.arc(id);
    const double rest = labels_.DistanceVia(a.to, target);
    if (a.cost + rest > left + slack) continue;
    if (best < 0 || rest < best_rest || (rest == best_rest && id < best)) {
      best = id;
      best_rest = rest;
    }
  }
  return best;
}

PointId HubLabelRouteTable::NextHop(PointId from, PointId to) const {
  if (!Known(from) || !Known(to) || from == to) return kNoPoint;
  const std::vector<double>& target = SpreadTo(Target(to));
  const double left = labels_.DistanceVia(from, target);
  if (left == kInf) return kNoPoint;
  const std::int32_t id = BestArc(from, target, left);
  if (id < 0) return kNoPoint;
  return map_->arc(graph_.map_arc[static_cast<std::size_t>(id)]).to;
}

Result<Route> HubLabelRouteTable::Path(PointId from, PointId to) const {
  if (!Known(from) || !Known(to)) return NoRouteError(*map_, from, to);
  if (from == to) return Route{{from}, {}, 0.0, 0.0};
  const VertexId sink = Target(to);
  const std::vector<double>& target = SpreadTo(sink);
  double left = labels_.DistanceVia(from, target);
  if (left == kInf) return NoRouteError(*map_, from, to);
  std::vector<VertexId> path{from};
  // Each hop leaves on a cheapest route; the sink (turn penalties) is not part of the route.
  for (VertexId v = from; v != to;) {
    const std::int32_t id = BestArc(v, target, left);
    if (id < 0 || path.size() > search().vertex_count()) {
      return Error{ErrorCode::kFailedPrecondition, "hub labels: no cheapest arc out of vertex " + std::to_string(v) +
                                                       " towards point " + std::to_string(to)};
    }
    const CostArc& a = search().arc(id);
    if (a.to == sink && graph_.expanded) break;
    left -= a.cost;
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
