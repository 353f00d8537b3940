#include "engine/planning/path_heat.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <queue>
#include <set>
#include <utility>

namespace dispatch::engine {

PathHeat PathHeat::FromUses(const WarehouseMap& map, const std::vector<LaneUse>& uses, double from, double period) {
  PathHeat h;
  const std::size_t lanes = map.paths().size();
  h.heat_.assign(lanes, 0);
  h.robots_.assign(lanes, 0);
  h.weight_.assign(lanes, 1.0);
  std::set<std::pair<int, int>> seen;  // (lane, robot)
  for (const LaneUse& u : uses) {
    if (u.arc < 0 || static_cast<std::size_t>(u.arc) >= map.arcs().size()) continue;
    if (u.time < from || u.time > from + period) continue;
    const std::int32_t lane = map.arc(u.arc).path;
    if (lane < 0 || static_cast<std::size_t>(lane) >= lanes) continue;
    ++h.heat_[static_cast<std::size_t>(lane)];
    if (seen.insert({lane, u.robot}).second) ++h.robots_[static_cast<std::size_t>(lane)];
  }
  double total = 0.0;  // Σ_j b_j · h_j
  for (std::size_t k = 0; k < lanes; ++k) total += static_cast<double>(h.robots_[k]) * h.heat_[k];
  if (total > 0.0) {
    for (std::size_t k = 0; k < lanes; ++k) {
      h.weight_[k] = 1.0 + (h.robots_[k] + 1.0) * h.heat_[k] / total;  // eqs. (13)-(14)
    }
  }
  return h;
}

double PathHeat::ArcWeight(const WarehouseMap& map, ArcId a) const {
  const std::int32_t lane = map.arc(a).path;
  return lane >= 0 && static_cast<std::size_t>(lane) < weight_.size() ? weight_[static_cast<std::size_t>(lane)] : 1.0;
}

Result<Route> HeatRoute(const WarehouseMap& map, const PathHeat& heat, PointId from, PointId to, double speed) {
  const std::size_t n = map.point_count();
  auto valid = [&](PointId p) { return p >= 0 && static_cast<std::size_t>(p) < n; };
  if (!valid(from) || !valid(to)) return NoRouteError(map, from, to);
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<double> dist(n, kInf);
  std::vector<ArcId> via(n, -1);
  using Item = std::pair<double, PointId>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
  dist[static_cast<std::size_t>(from)] = 0.0;
  open.push({0.0, from});
  while (!open.empty()) {
    const auto [d, u] = open.top();
    open.pop();
    if (d > dist[static_cast<std::size_t>(u)]) continue;
    if (u == to) break;
    for (ArcId a : map.out_arcs(u)) {
      const Arc& arc = map.arc(a);
      const double nd = d + arc.length * heat.ArcWeight(map, a);
      if (nd < dist[static_cast<std::size_t>(arc.to)]) {
        dist[static_cast<std::size_t>(arc.to)] = nd;
        via[static_cast<std::size_t>(arc.to)] = a;
        open.push({nd, arc.to});
      }
    }
  }
  if (std::isinf(dist[static_cast<std::size_t>(to)])) return NoRouteError(map, from, to);
  Route r;
  for (PointId p = to; p != from; p = map.arc(via[static_cast<std::size_t>(p)]).from) {
    r.points.push_back(p);
    r.arcs.push_back(via[static_cast<std::size_t>(p)]);
  }
  r.points.push_back(from);
  std::reverse(r.points.begin(), r.points.end());
  std::reverse(r.arcs.begin(), r.arcs.end());
  for (ArcId a : r.arcs) {
    const Arc& arc = map.arc(a);
    r.length += arc.length;
    r.cost += arc.length / (arc.max_speed > 0.0 ? std::min(speed, arc.max_speed) : speed);
  }
  return r;
}

}  // namespace dispatch::engine
