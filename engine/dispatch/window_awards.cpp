#include "engine/dispatch/window_awards.h"

#include <algorithm>

#include "engine/planning/window_planner.h"

namespace dispatch::engine {
namespace {

constexpr std::size_t kNone = static_cast<std::size_t>(-1);

// The visits of `w` as a route the table accepts: waypoints at one point in a row are one
// visit, no arrival faster than its arc allows, the last visit for ever. Empty when two
// points in a row are not joined by an arc (the plan is then not reserved).
TimedRoute VisitsOf(const WarehouseMap& map, const TimeWindowRules& rules, const std::vector<Waypoint>& w) {
  TimedRoute r;
  for (const Waypoint& x : w) {
    if (!r.empty() && r.back().point == x.point) {
      r.back().depart = std::max(r.back().depart, x.departure());
      continue;
    }
    double arrive = x.eta;
    if (!r.empty()) {
      const auto arc = map.FindArc(r.back().point, x.point);
      if (!arc) return {};
      arrive = std::max(arrive, r.back().depart + DriveTime(map, rules, *arc));
    }
    r.push_back({x.point, arrive, std::max(arrive, x.departure())});
  }
  if (!r.empty()) r.back().depart = kForever;
  return r;
}

// The re-planned segment as waypoints (see the header: waits become departures). `fresh`:
// the segment starts with the robot's start waypoint; else it follows its queue, which it
// leaves at `ready`.
std::vector<Waypoint> SegmentOf(const WarehouseMap& map, const WindowPlan& plan, const std::vector<Waypoint>& stops,
                                bool fresh, double ready, const Waypoint& first) {
  std::vector<Waypoint> out;
  const TimedRoute& r = plan.route;
  std::size_t next_stop = 0;
  for (std::size_t v = 0; v < r.size(); ++v) {
    const bool last = v + 1 == r.size();
    Waypoint wp;
    wp.point = r[v].point;
    wp.xy = map.point(wp.point).position;
    wp.action = WaypointAction::kMove;
    wp.eta = last ? r[v].arrive : r[v].depart;
    if (v == 0) {
      if (fresh) {
        wp.action = first.action;
        out.push_back(wp);
      } else if (r[0].depart > ready + 1e-6) {
        out.push_back(wp);  // it waits where its queue ended
      }
      continue;
    }
    if (next_stop < stops.size() && next_stop < plan.stop_visits.size() && plan.stop_visits[next_stop] == v) {
      const Waypoint& stop = stops[next_stop++];
      wp.action = stop.action;
      wp.dwell = stop.dwell;
      wp.eta = last ? r[v].arrive : r[v].depart - stop.dwell;
    }
    out.push_back(wp);
  }
  return out;
}

}  // namespace

void PlanAwardsInWindows(const std::shared_ptr<const WarehouseMap>& map, const RouteTable& routes,
                         const AllocationConfig& config, const FleetState& fleet, const RoundSegments& segments,
                         double now, std::vector<RoundAward>& awards, std::vector<std::string>& notes) {
  TimeWindowRules rules = config.windows;
  rules.speed = config.speed;
  rules.turn_s_per_90 = config.turn_time;
  ReservationTable table(map, rules);
  const std::size_t n = fleet.robot_count();
  std::vector<bool> replan(n, false);
  std::vector<std::vector<Waypoint>> kept(n);  // each robot's plan as reserved so far
  auto reserve = [&](std::size_t i) {
    const TimedRoute route = VisitsOf(*map, rules, kept[i]);
    if (route.empty() || !table.Reserve(static_cast<int>(i), route).ok()) {
      table.Release(static_cast<int>(i));
      return false;
    }
    return true;
  };
  for (std::size_t i = 0; i < n; ++i) {
    const auto& w = fleet.plan(i).waypoints;
    const std::size_t first = i < segments.first_new.size() ? segments.first_new[i] : kNone;
    replan[i] = first != kNone && !segments.in_formation[i];
    // A robot without a queue keeps its start waypoint; its new segment repeats it.
    const std::size_t upto = replan[i] ? std::max<std::size_t>(first, 1) : w.size();
    kept[i].assign(w.begin(), w.begin() + static_cast<std::ptrdiff_t>(std::min(upto, w.size())));
    if (!reserve(i) && replan[i]) {
      replan[i] = false;
      notes.push_back("time windows: the plan of " + fleet.robot_id(i) + " is not a route of the map; its awards keep the strategy's routes");
    }
  }
  for (RoundAward& a : awards) {
    if (a.award.winners.size() != 1 || a.segments.size() != 1) continue;
    const auto found = fleet.FindRobot(a.award.winners[0]);
    if (!found || !replan[*found]) continue;
    const std::size_t i = *found;
    std::vector<Waypoint>& segment = a.segments[0];
    if (segment.empty()) continue;
    const bool fresh = kept[i].size() == 1 && segment.front().point == kept[i].front().point &&
                       segment.front().seq == kept[i].front().seq;
    const Waypoint& end = kept[i].back();
    const double ready = fresh ? now : std::max(end.eta, end.departure());
    WindowRequest request;
    request.robot = static_cast<int>(i);
    request.start = end.point;
    request.start_time = ready;
    std::vector<Waypoint> stops;
    for (const Waypoint& w : segment) {
      if (w.action == WaypointAction::kPick || w.action == WaypointAction::kDrop) {
        stops.push_back(w);
        request.stops.push_back({w.point, w.dwell});
      }
    }
    auto plan = request.stops.empty() ? Result<WindowPlan>(InvalidArgument("no stops"))
                                      : PlanInWindows(table, routes, request);
    if (plan.ok()) {
      segment = SegmentOf(*map, plan.value(), stops, fresh, ready, segment.front());
      if (!fresh) a.after_departure[0] = ready;
    } else {
      notes.push_back("order " + a.order_id + ": time windows: " + plan.error().message + "; the strategy's route kept");
    }
    if (fresh) kept[i].clear();
    kept[i].insert(kept[i].end(), segment.begin(), segment.end());
    reserve(i);
  }
}

}  // namespace dispatch::engine
