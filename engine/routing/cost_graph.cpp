#include "engine/routing/cost_graph.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

namespace dispatch::engine {

Result<CostGraph> CostGraph::Build(std::size_t vertex_count, std::vector<CostArc> arcs) {
  if (vertex_count > static_cast<std::size_t>(std::numeric_limits<VertexId>::max()) ||
      arcs.size() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max())) {
    return InvalidArgument("cost graph too large for 32-bit ids");
  }
  for (std::size_t i = 0; i < arcs.size(); ++i) {
    const CostArc& a = arcs[i];
    if (a.from < 0 || a.to < 0 || static_cast<std::size_t>(a.from) >= vertex_count ||
        static_cast<std::size_t>(a.to) >= vertex_count) {
      return InvalidArgument("cost graph arc " + std::to_string(i) + " (" +
                             std::to_string(a.from) + " -> " + std::to_string(a.to) +
                             "): vertex out of range [0, " + std::to_string(vertex_count) + ")");
    }
    if (!(a.cost >= 0.0) || !std::isfinite(a.cost)) {
      return InvalidArgument("cost graph arc " + std::to_string(i) + ": cost " +
                             std::to_string(a.cost) + " is not finite and >= 0");
    }
  }
  CostGraph g;
  g.vertex_count_ = vertex_count;
  g.arcs_ = std::move(arcs);
  if (!g.arcs_.empty() && g.arcs_.front().cost > 0.0 &&
      std::all_of(g.arcs_.begin(), g.arcs_.end(), [&](const CostArc& a) { return a.cost == g.arcs_.front().cost; })) {
    g.uniform_cost_ = g.arcs_.front().cost;
  }
  // Counting sort of arc ids by tail (out) and head (in): CSR with ids kept in input order.
  auto csr = [&](auto end_of, std::vector<std::size_t>& begin, std::vector<std::int32_t>& ids) {
    begin.assign(vertex_count + 1, 0);
    for (const CostArc& a : g.arcs_) ++begin[static_cast<std::size_t>(end_of(a)) + 1];
    for (std::size_t v = 0; v < vertex_count; ++v) begin[v + 1] += begin[v];
    std::vector<std::size_t> fill(begin.begin(), begin.end() - 1);
    ids.resize(g.arcs_.size());
    for (std::size_t i = 0; i < g.arcs_.size(); ++i) {
      ids[fill[static_cast<std::size_t>(end_of(g.arcs_[i]))]++] = static_cast<std::int32_t>(i);
    }
  };
  csr([](const CostArc& a) { return a.from; }, g.out_begin_, g.out_ids_);
  csr([](const CostArc& a) { return a.to; }, g.in_begin_, g.in_ids_);
  return g;
}

std::int32_t CostGraph::CheapestArc(VertexId from, VertexId to) const {
  std::int32_t best = -1;
  for (std::int32_t id : out_arcs(from)) {
    if (arc(id).to == to && (best < 0 || arc(id).cost < arc(best).cost)) best = id;
  }
  return best;
}

std::vector<VertexId> MapCostGraph::TargetVertices(const WarehouseMap& map, PointId p) const {
  std::vector<VertexId> targets{p};
  if (expanded) {
    for (ArcId e : map.in_arcs(p)) targets.push_back(static_cast<VertexId>(point_count) + e);
  }
  return targets;
}

double TurnAngle(const WarehouseMap& map, ArcId in, ArcId out) {
  const Arc& a = map.arc(in);
  const Arc& b = map.arc(out);
  const Eigen::Vector2d ha = map.point(a.to).position - map.point(a.from).position;
  const Eigen::Vector2d hb = map.point(b.to).position - map.point(b.from).position;
  const double norms = ha.norm() * hb.norm();
  if (!(norms > 0.0)) return 0.0;
  // atan2 of cross and dot is accurate near 0 and pi, unlike acos.
  const double cross = ha.x() * hb.y() - ha.y() * hb.x();
  return std::abs(std::atan2(cross, ha.dot(hb)));
}

Result<MapCostGraph> BuildMapCostGraph(const WarehouseMap& map, const RouteTableOptions& options) {
  if (!(options.speed > 0.0) || !std::isfinite(options.speed)) {
    return InvalidArgument("route table speed must be finite and > 0, got " +
                           std::to_string(options.speed));
  }
  if (!(options.turn_penalty_s >= 0.0) || !std::isfinite(options.turn_penalty_s)) {
    return InvalidArgument("route table turn_penalty_s must be finite and >= 0, got " +
                           std::to_string(options.turn_penalty_s));
  }
  const std::vector<Arc>& arcs = map.arcs();
  std::vector<double> arc_cost(arcs.size());
  for (std::size_t i = 0; i < arcs.size(); ++i) {
    const double v = arcs[i].max_speed > 0.0 ? std::min(options.speed, arcs[i].max_speed)
                                             : options.speed;
    arc_cost[i] = arcs[i].length / v;
  }
  MapCostGraph g;
  g.point_count = map.point_count();
  g.expanded = options.turn_penalty_s > 0.0;
  g.speed = options.speed;
  std::vector<CostArc> cost_arcs;
  std::size_t vertex_count = g.point_count;
  if (!g.expanded) {
    cost_arcs.reserve(arcs.size());
    for (std::size_t i = 0; i < arcs.size(); ++i) {
      cost_arcs.push_back({arcs[i].from, arcs[i].to, arc_cost[i]});
      g.map_arc.push_back(static_cast<ArcId>(i));
    }
  } else {
    vertex_count += arcs.size();
    if (vertex_count > static_cast<std::size_t>(std::numeric_limits<VertexId>::max())) {
      return InvalidArgument("map too large for the turn-expanded route graph");
    }
    const auto pc = static_cast<VertexId>(g.point_count);
    const double per_radian = options.turn_penalty_s / (std::numbers::pi / 2.0);
    for (std::size_t p = 0; p < g.point_count; ++p) {
      for (ArcId a : map.out_arcs(static_cast<PointId>(p))) {
        cost_arcs.push_back({static_cast<VertexId>(p), pc + a, arc_cost[a]});
        g.map_arc.push_back(a);
      }
    }
    for (std::size_t i = 0; i < arcs.size(); ++i) {
      const auto a = static_cast<ArcId>(i);
      for (ArcId b : map.out_arcs(arcs[i].to)) {
        const double turn = per_radian * TurnAngle(map, a, b);
        cost_arcs.push_back({pc + a, pc + b, arc_cost[b] + turn});
        g.map_arc.push_back(b);
      }
    }
  }
  auto graph = CostGraph::Build(vertex_count, std::move(cost_arcs));
  if (!graph.ok()) return graph.error();
  g.graph = std::move(graph).value();
  return g;
}

Route RouteFromVertexPath(const WarehouseMap& map, const MapCostGraph& g,
                          std::span<const VertexId> path) {
  Route route;
  route.points.push_back(path.front());
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    const std::int32_t id = g.graph.CheapestArc(path[i], path[i + 1]);
    const ArcId a = g.map_arc[static_cast<std::size_t>(id)];
    route.arcs.push_back(a);
    route.points.push_back(map.arc(a).to);
    route.cost += g.graph.arc(id).cost;
    route.length += map.arc(a).length;
  }
  return route;
}

}  // namespace dispatch::engine
