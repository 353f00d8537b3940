#include "engine/fleet/plan.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <limits>
#include <stdexcept>

#include "engine/routing/cost_graph.h"

namespace dispatch::engine {
namespace {

bool ValidPoint(const WarehouseMap& map, PointId id) {
  return id >= 0 && static_cast<std::size_t>(id) < map.point_count();
}

void Append(Plan& plan, PointId point, const Eigen::Vector2d& xy, double eta,
            WaypointAction action, double dwell) {
  Waypoint w;
  w.seq = static_cast<int>(plan.waypoints.size());
  w.point = point;
  w.xy = xy;
  w.eta = eta;
  w.action = action;
  w.dwell = dwell;
  plan.waypoints.push_back(w);
}

Status CheckDrive(double speed, double start_time, double turn_time) {
  if (!std::isfinite(speed) || speed <= 0.0) {
    return InvalidArgument("speed must be > 0 m/s, got " + std::to_string(speed));
  }
  if (!std::isfinite(start_time)) return InvalidArgument("start time is not finite");
  if (!std::isfinite(turn_time) || turn_time < 0.0) {
    return InvalidArgument("turn time must be finite and >= 0 s, got " + std::to_string(turn_time));
  }
  return Ok{};
}

// Builds a plan stop by stop: drives the RouteTable's route from the last stop to the next,
// timing arcs by length / speed (capped by an arc's own max_speed) plus the turning time.
struct PlanDriver {
  PlanDriver(const WarehouseMap& map, const RouteTable& routes, PointId start, double start_time, double speed,
             double turn_time)
      : map(map), routes(routes), speed(speed), turn_time(turn_time), at(start), time(start_time) {
    Append(plan, start, map.point(start).position, start_time, WaypointAction::kMove, 0.0);
  }
  // Drives from `at` to `stop`, then works `dwell` there.
  Status Visit(PointId stop, WaypointAction action, double dwell) {
    Result<Route> route = routes.Path(at, stop);
    if (!route.ok()) return route.error();
    const Route& r = *route;
    for (std::size_t i = 0; i < r.arcs.size(); ++i) {
      const Arc& arc = map.arc(r.arcs[i]);
      const double v = arc.max_speed > 0.0 ? std::min(speed, arc.max_speed) : speed;
      if (turn_time > 0.0 && last_arc >= 0) {
        time += turn_time * TurnAngle(map, last_arc, r.arcs[i]) / (std::numbers::pi / 2.0);
      }
      last_arc = r.arcs[i];
      time += arc.length / v;
      const PointId p = r.points[i + 1];
      if (i + 1 < r.arcs.size()) Append(plan, p, map.point(p).position, time, WaypointAction::kMove, 0.0);
    }
    Append(plan, stop, map.point(stop).position, time, action, dwell);
    time += dwell;
    at = stop;
    return Ok{};
  }

  const WarehouseMap& map;
  const RouteTable& routes;
  const double speed, turn_time;
  Plan plan;
  PointId at;
  double time;
  ArcId last_arc = -1;  // the arc the robot came by (turning time from its heading)
};

}  // namespace

const char* WaypointActionName(WaypointAction action) {
  switch (action) {
    case WaypointAction::kMove: return "move";
    case WaypointAction::kPick: return "pick";
    case WaypointAction::kDrop: return "drop";
    case WaypointAction::kWait: return "wait";
    case WaypointAction::kPark: return "park";
    case WaypointAction::kCharge: return "charge";
  }
  return "unknown";
}

std::optional<WaypointAction> ParseWaypointAction(std::string_view name) {
  for (WaypointAction a : {WaypointAction::kMove, WaypointAction::kPick, WaypointAction::kDrop,
                           WaypointAction::kWait, WaypointAction::kPark, WaypointAction::kCharge}) {
    if (name == WaypointActionName(a)) return a;
  }
  return std::nullopt;
}

std::size_t FindSequence(const std::vector<Waypoint>& w, std::uint64_t seq) {
  constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  if (w.empty() || seq > static_cast<std::uint64_t>(std::numeric_limits<int>::max())) return kNone;
  const int s = static_cast<int>(seq);
  const std::size_t guess = static_cast<std::size_t>(static_cast<std::int64_t>(s) - w.front().seq);
  if (guess < w.size() && w[guess].seq == s) return guess;  // numbered without gaps
  // Numbered without gaps from s to the end (a plan rewritten before s, e.g. a detour).
  const std::size_t from_back = w.size() - 1 - static_cast<std::size_t>(static_cast<std::int64_t>(w.back().seq) - s);
  if (from_back < w.size() && w[from_back].seq == s) return from_back;
  auto at = std::lower_bound(w.begin(), w.end(), s, [](const Waypoint& x, int v) { return x.seq < v; });
  if (at != w.end() && at->seq == s) return static_cast<std::size_t>(at - w.begin());
  // Not found by halving: absent, or a plan out of order (then only a scan finds it).
  for (std::size_t i = 0; i < w.size(); ++i) {
    if (w[i].seq == s) return i;
  }
  return kNone;
}

Eigen::Vector2d Plan::PositionAt(double t) const {
  if (waypoints.empty()) throw std::logic_error("Plan::PositionAt on an empty plan");
  if (t <= waypoints.front().eta) return waypoints.front().xy;
  // The last waypoint whose arrival is <= t.
  auto next = std::upper_bound(waypoints.begin(), waypoints.end(), t,
                               [](double time, const Waypoint& w) { return time < w.eta; });
  const Waypoint& from = *(next - 1);
  if (next == waypoints.end() || t <= from.departure()) return from.xy;
  const Waypoint& to = *next;
  const double span = to.eta - from.departure();
  if (span <= 0.0) return to.xy;
  const double s = (t - from.departure()) / span;
  return from.xy + s * (to.xy - from.xy);
}

double Plan::start_time() const {
  if (waypoints.empty()) throw std::logic_error("Plan::start_time on an empty plan");
  return waypoints.front().eta;
}

double Plan::end_time() const {
  if (waypoints.empty()) throw std::logic_error("Plan::end_time on an empty plan");
  return waypoints.back().departure();
}

int TaskPointCount(const PlanTask& task) { return static_cast<int>(task.picks.size()); }

double TaskWorkTime(const PlanTask& task) {
  return TaskPointCount(task) * task.work_time + task.drop_time;
}

Result<Plan> BuildPlan(const WarehouseMap& map, const RouteTable& routes, PointId start,
                       double start_time, double speed, const std::vector<PlanTask>& tasks,
                       double turn_time) {
  if (Status s = CheckDrive(speed, start_time, turn_time); !s.ok()) return s.error();
  if (!ValidPoint(map, start)) return NotFound("unknown start point id " + std::to_string(start));
  for (std::size_t k = 0; k < tasks.size(); ++k) {
    const PlanTask& task = tasks[k];
    const std::string what = "task " + std::to_string(k + 1) + ": ";
    if (task.picks.empty()) return InvalidArgument(what + "no pick points");
    if (!std::isfinite(task.work_time) || task.work_time < 0.0) {
      return InvalidArgument(what + "work time must be >= 0 s, got " +
                             std::to_string(task.work_time));
    }
    if (!std::isfinite(task.drop_time) || task.drop_time < 0.0) {
      return InvalidArgument(what + "drop time must be >= 0 s, got " +
                             std::to_string(task.drop_time));
    }
    for (PointId p : task.picks) {
      if (!ValidPoint(map, p)) return NotFound(what + "unknown pick point id " + std::to_string(p));
    }
    if (!ValidPoint(map, task.drop)) {
      return NotFound(what + "unknown drop point id " + std::to_string(task.drop));
    }
  }

  PlanDriver driver(map, routes, start, start_time, speed, turn_time);
  for (std::size_t k = 0; k < tasks.size(); ++k) {
    const PlanTask& task = tasks[k];
    const std::string what = "task " + std::to_string(k + 1);
    for (std::size_t i = 0; i < task.picks.size(); ++i) {
      if (Status s = driver.Visit(task.picks[i], WaypointAction::kPick, task.work_time); !s.ok()) {
        return Error{s.error().code,
                     what + ", pick " + std::to_string(i + 1) + ": " + s.error().message};
      }
    }
    if (Status s = driver.Visit(task.drop, WaypointAction::kDrop, task.drop_time); !s.ok()) {
      return Error{s.error().code, what + ", drop: " + s.error().message};
    }
  }
  return std::move(driver.plan);
}

Result<Plan> BuildTrip(const WarehouseMap& map, const RouteTable& routes, PointId start, double start_time,
                       double speed, PointId to, WaypointAction action, double turn_time) {
  if (Status s = CheckDrive(speed, start_time, turn_time); !s.ok()) return s.error();
  if (!ValidPoint(map, start)) return NotFound("unknown start point id " + std::to_string(start));
  if (!ValidPoint(map, to)) return NotFound("unknown destination point id " + std::to_string(to));
  PlanDriver driver(map, routes, start, start_time, speed, turn_time);
  if (to == start) {  // already there: the start waypoint says what it is for
    driver.plan.waypoints.back().action = action;
    return std::move(driver.plan);
  }
  if (Status s = driver.Visit(to, action, 0.0); !s.ok()) return s.error();
  return std::move(driver.plan);
}

}  // namespace dispatch::engine
