#include "engine/dispatch/heat_awards.h"

#include <algorithm>
#include <numbers>

#include "engine/planning/path_heat.h"
#include "engine/routing/cost_graph.h"

namespace dispatch::engine {
namespace {

// Every arc driven by every plan, with the time it is entered.
std::vector<LaneUse> UsesOf(const WarehouseMap& map, const FleetState& fleet) {
  std::vector<LaneUse> uses;
  for (std::size_t i = 0; i < fleet.robot_count(); ++i) {
    const auto& w = fleet.plan(i).waypoints;
    for (std::size_t k = 1; k < w.size(); ++k) {
      if (w[k].point == w[k - 1].point) continue;
      if (const auto a = map.FindArc(w[k - 1].point, w[k].point)) {
        uses.push_back({*a, static_cast<int>(i), w[k - 1].departure()});
      }
    }
  }
  return uses;
}

}  // namespace

Status UseHeatRoutes(std::shared_ptr<const WarehouseMap> map, const AllocationConfig& config, FleetState& fleet,
                     double now) {
  const PathHeat heat = PathHeat::FromUses(*map, UsesOf(*map, fleet), now, config.heat_period);
  bool hot = false;
  for (std::size_t lane = 0; lane < heat.lanes() && !hot; ++lane) hot = heat.Weight(lane) != 1.0;
  if (!hot) return Ok{};
  RouteTableOptions options;
  options.speed = config.speed;
  options.turn_penalty_s = config.turn_time;
  auto table = HeatRouteTable(std::move(map), heat, options);
  if (!table.ok()) return table.error();
  return fleet.UseRoutes(std::shared_ptr<const RouteTable>(std::move(table).value()));
}

void RouteAwardsByHeat(const WarehouseMap& map, const AllocationConfig& config, const FleetState& fleet,
                       const RoundSegments& segments, double now, std::vector<RoundAward>& awards,
                       std::vector<std::string>& notes) {
  const PathHeat heat = PathHeat::FromUses(map, UsesOf(map, fleet), now, config.heat_period);
  // Per robot: where and when its next new segment starts (its queue's end, then the end of
  // the segment before it in this round).
  std::vector<PointId> at(fleet.robot_count(), kNoPoint);
  std::vector<double> free_at(fleet.robot_count(), now);
  for (std::size_t i = 0; i < fleet.robot_count(); ++i) {
    const std::size_t first = i < segments.first_new.size() ? segments.first_new[i] : RoundSegments::kNothingNew;
    const auto& w = fleet.plan(i).waypoints;
    if (first == RoundSegments::kNothingNew || w.empty()) continue;
    const Waypoint& before = w[first > 0 ? first - 1 : 0];
    at[i] = before.point;
    free_at[i] = first > 0 ? before.departure() : before.eta;
  }
  for (RoundAward& a : awards) {
    if (a.award.winners.size() != 1) {  // a formation keeps its routes; its members go on from its end
      for (std::size_t k = 0; k < a.award.winners.size() && k < a.segments.size(); ++k) {
        const auto member = fleet.FindRobot(a.award.winners[k]);
        if (!member || a.segments[k].empty()) continue;
        at[*member] = a.segments[k].back().point;
        free_at[*member] = a.segments[k].back().departure();
      }
      continue;
    }
    if (a.segments.size() != 1 || a.segments[0].empty()) continue;
    const auto found = fleet.FindRobot(a.award.winners[0]);
    if (!found || at[*found] == kNoPoint) continue;
    const std::size_t i = *found;
    const std::vector<Waypoint>& old = a.segments[0];
    const bool fresh = a.after_departure[0] == 0.0 && old.front().point == at[i] && old.front().action == WaypointAction::kMove;
    std::vector<Waypoint> out;
    double clock = fresh ? old.front().eta : free_at[i];
    if (fresh) out.push_back(old.front());
    PointId from = at[i];
    ArcId last_arc = -1;
    bool ok = true;
    for (std::size_t k = fresh ? 1 : 0; k < old.size() && ok; ++k) {
      const Waypoint& stop = old[k];
      if (stop.action != WaypointAction::kPick && stop.action != WaypointAction::kDrop) continue;
      auto route = HeatRoute(map, heat, from, stop.point, config.speed, config.turn_time, last_arc);
      if (!route.ok()) {
        ok = false;
        notes.push_back("order " + a.order_id + ": heat routing: " + route.error().message + "; the table's route kept");
        break;
      }
      for (std::size_t p = 1; p < route->points.size(); ++p) {
        const ArcId a_id = route->arcs[p - 1];
        const Arc& arc = map.arc(a_id);
        if (config.turn_time > 0.0 && last_arc >= 0) {
          clock += config.turn_time * TurnAngle(map, last_arc, a_id) / (std::numbers::pi / 2.0);  // as BuildPlan
        }
        last_arc = a_id;
        clock += arc.length / (arc.max_speed > 0.0 ? std::min(config.speed, arc.max_speed) : config.speed);
        Waypoint wp;
        wp.point = route->points[p];
        wp.xy = map.point(wp.point).position;
        wp.eta = clock;
        wp.action = WaypointAction::kMove;
        out.push_back(wp);
      }
      if (out.empty() || out.back().point != stop.point) {  // a stop where it already stands
        Waypoint wp = stop;
        wp.eta = clock;
        out.push_back(wp);
      } else {
        out.back().action = stop.action;
        out.back().dwell = stop.dwell;
      }
      clock += stop.dwell;
      from = stop.point;
    }
    if (!ok) continue;
    a.segments[0] = std::move(out);
    at[i] = from;
    free_at[i] = clock;
  }
}

}  // namespace dispatch::engine
