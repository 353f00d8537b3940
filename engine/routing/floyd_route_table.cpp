#include "engine/routing/floyd_route_table.h"

#include <limits>
#include <string>

#include "engine/routing/dijkstra.h"

namespace dispatch::engine {

Result<std::unique_ptr<FloydRouteTable>> FloydRouteTable::Build(
    std::shared_ptr<const WarehouseMap> map, const RouteTableOptions& options,
    const CancelCheck& cancelled) {
  if (!map) return InvalidArgument("FloydRouteTable: null map");
  auto graph = BuildMapCostGraph(*map, options);
  if (!graph.ok()) return graph.error();
  std::unique_ptr<FloydRouteTable> t(new FloydRouteTable());
  t->map_ = std::move(map);
  t->graph_ = std::move(graph).value();
  const bool dijkstra = options.method == RouteTableMethod::kDijkstra;
  t->method_ = dijkstra ? "dijkstra" : "floyd";
  auto table = dijkstra ? AllPairsDijkstra(t->graph_.graph, options.threads, cancelled)
                        : FloydBlocked(t->graph_.graph, options.threads, cancelled);
  if (!table.ok()) return table.error();
  t->table_ = std::move(table).value();

  if (t->graph_.expanded) {
    // Distance u -> v = min(0 if u == v, min over in-arcs e of v of D[u][P+e]).
    const std::size_t pc = t->graph_.point_count;
    t->point_cost_.assign(pc * pc, std::numeric_limits<float>::infinity());
    t->point_arrival_.assign(pc * pc, kNoVertex);
    for (std::size_t v = 0; v < pc; ++v) {
      const std::vector<VertexId> targets =
          t->graph_.TargetVertices(*t->map_, static_cast<PointId>(v));
      for (std::size_t u = 0; u < pc; ++u) {
        float best = std::numeric_limits<float>::infinity();
        VertexId arrival = kNoVertex;
        for (VertexId x : targets) {
          const float d = t->table_.Dist(static_cast<VertexId>(u), x);
          if (d < best) {
            best = d;
            arrival = x;
          }
        }
        t->point_cost_[u * pc + v] = best;
        t->point_arrival_[u * pc + v] = arrival;
      }
    }
  }
  return t;
}

VertexId FloydRouteTable::Arrival(PointId from, PointId to) const {
  if (!graph_.expanded) {
    return table_.Next(from, to) == kNoVertex ? kNoVertex : to;
  }
  return point_arrival_[static_cast<std::size_t>(from) * graph_.point_count +
                        static_cast<std::size_t>(to)];
}

double FloydRouteTable::Cost(PointId from, PointId to) const {
  if (!Known(from) || !Known(to)) return std::numeric_limits<double>::infinity();
  if (!graph_.expanded) return table_.Dist(from, to);
  return point_cost_[static_cast<std::size_t>(from) * graph_.point_count +
                     static_cast<std::size_t>(to)];
}

PointId FloydRouteTable::NextHop(PointId from, PointId to) const {
  if (!Known(from) || !Known(to) || from == to) return kNoPoint;
  const VertexId arrival = Arrival(from, to);
  if (arrival == kNoVertex) return kNoPoint;
  const VertexId hop = table_.Next(from, arrival);
  if (!graph_.expanded) return hop;
  // The first hop of a point vertex is the arc vertex of its first arc.
  return map_->arc(hop - static_cast<VertexId>(graph_.point_count)).to;
}

Result<Route> FloydRouteTable::Path(PointId from, PointId to) const {
  if (!Known(from) || !Known(to)) {
    return NoRouteError(*map_, from, to);
  }
  const VertexId arrival = Arrival(from, to);
  std::vector<VertexId> path;
  if (arrival != kNoVertex) path = WalkNext(table_, from, arrival);
  if (path.empty()) {
    return NoRouteError(*map_, from, to);
  }
  return RouteFromVertexPath(*map_, graph_, path);
}

RouteTableBuildInfo FloydRouteTable::build_info() const {
  return {method_,
          graph_.point_count,
          graph_.graph.vertex_count(),
          graph_.graph.arc_count(),
          graph_.expanded,
          table_.bytes() + point_cost_.size() * sizeof(float) +
              point_arrival_.size() * sizeof(VertexId),
          graph_.speed};
}

}  // namespace dispatch::engine
