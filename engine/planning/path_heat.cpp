#include "engine/planning/path_heat.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numbers>
#include <queue>
#include <set>
#include <utility>

#include "engine/routing/cost_graph.h"
#include "engine/routing/lazy_route_table.h"

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

Result<Route> HeatRoute(const WarehouseMap& map, const PathHeat& heat, PointId from, PointId to, double speed,
                        double turn_s_per_90, ArcId arrived_by) {
  const std::size_t n = map.point_count();
  auto valid = [&](PointId p) { return p >= 0 && static_cast<std::size_t>(p) < n; };
  if (!valid(from) || !valid(to)) return NoRouteError(map, from, to);
  if (arrived_by >= 0 && (static_cast<std::size_t>(arrived_by) >= map.arcs().size() || map.arc(arrived_by).to != from)) {
    arrived_by = -1;  // not an arc into `from`: heading unknown
  }
  // Without turning time a state is a point; with it, the arc a robot arrived by (the start
  // is one more state), so a turn's cost is known when the next arc is chosen.
  const bool turns = turn_s_per_90 > 0.0;
  const std::size_t states = turns ? map.arcs().size() + 1 : n;
  const std::size_t start = turns ? map.arcs().size() : static_cast<std::size_t>(from);
  auto state_of = [&](ArcId a) { return turns ? static_cast<std::size_t>(a) : static_cast<std::size_t>(map.arc(a).to); };
  auto drive = [&](const Arc& arc) {
    return arc.length / (arc.max_speed > 0.0 ? std::min(speed, arc.max_speed) : speed);
  };
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<double> dist(states, kInf);
  std::vector<ArcId> via(states, -1);          // the arc that reached the state
  std::vector<std::size_t> parent(states, start);
  using Item = std::pair<double, std::size_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
  dist[start] = 0.0;
  open.push({0.0, start});
  std::size_t goal = states;
  while (!open.empty()) {
    const auto [d, s] = open.top();
    open.pop();
    if (d > dist[s]) continue;
    const ArcId in = s == start ? arrived_by : via[s];
    const PointId at = s == start ? from : map.arc(via[s]).to;
    if (at == to) {
      goal = s;
      break;
    }
    for (ArcId b : map.out_arcs(at)) {
      const Arc& arc = map.arc(b);
      double nd = d + drive(arc) * heat.ArcWeight(map, b);
      if (turns && in >= 0) nd += turn_s_per_90 * TurnAngle(map, in, b) / (std::numbers::pi / 2.0);
      const std::size_t next = state_of(b);
      if (nd < dist[next]) {
        dist[next] = nd;
        via[next] = b;
        parent[next] = s;
        open.push({nd, next});
      }
    }
  }
  if (goal == states) return NoRouteError(map, from, to);
  Route r;
  for (std::size_t s = goal; s != start; s = parent[s]) {
    r.points.push_back(map.arc(via[s]).to);
    r.arcs.push_back(via[s]);
  }
  r.points.push_back(from);
  std::reverse(r.points.begin(), r.points.end());
  std::reverse(r.arcs.begin(), r.arcs.end());
  ArcId last = arrived_by;
  for (ArcId a : r.arcs) {
    const Arc& arc = map.arc(a);
    r.length += arc.length;
    r.cost += drive(arc);
    if (turns && last >= 0) r.cost += turn_s_per_90 * TurnAngle(map, last, a) / (std::numbers::pi / 2.0);
    last = a;
  }
  return r;
}

Result<std::unique_ptr<RouteTable>> HeatRouteTable(std::shared_ptr<const WarehouseMap> map, const PathHeat& heat,
                                                   const RouteTableOptions& options) {
  if (!map) return InvalidArgument("heat route table: null map");
  std::vector<double> weight(map->arcs().size());
  for (std::size_t a = 0; a < weight.size(); ++a) weight[a] = heat.ArcWeight(*map, static_cast<ArcId>(a));
  auto table = LazyRouteTable::BuildWeighted(std::move(map), options, weight);
  if (!table.ok()) return table.error();
  return std::unique_ptr<RouteTable>(std::move(table).value());
}

}  // namespace dispatch::engine
