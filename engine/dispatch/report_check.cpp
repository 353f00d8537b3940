#include "engine/dispatch/report_check.h"

#include <cstdio>

namespace dispatch::engine {
namespace {

std::string Metres(double m) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f m", m);
  return buf;
}

ReportVerdict No(std::string why) { return {false, false, 0, std::move(why)}; }

}  // namespace

ReportVerdict CheckReached(const Assignment& a, std::uint64_t seq, std::uint64_t released_up_to,
                           const std::optional<Eigen::Vector2d>& pose, double tolerance) {
  const std::size_t i = FindWaypoint(a, seq);
  if (i == static_cast<std::size_t>(-1)) {
    return No("waypoint " + std::to_string(seq) + " is not in its current plan");
  }
  if (seq > released_up_to) {
    return No("waypoint " + std::to_string(seq) + " was not released to it (released up to " +
              std::to_string(released_up_to) + ")");
  }
  const Eigen::Vector2d& at = a.plan.waypoints[i].xy;
  if (pose) {
    const double off = pose->allFinite() ? (*pose - at).norm() : -1.0;
    if (off < 0.0 || off > tolerance) {
      return No("its pose is " + (off < 0.0 ? std::string("not finite") : Metres(off)) + " from waypoint " +
                std::to_string(seq) + " (tolerance " + Metres(tolerance) + ")");
    }
  }
  return {true, false, i, {}};
}

ReportVerdict CheckTaskEvent(const Assignment& a, const std::string& order_id, bool dropped,
                             std::uint64_t last_reached, const Eigen::Vector2d& robot_xy, double tolerance) {
  const WaypointAction action = dropped ? WaypointAction::kDrop : WaypointAction::kPick;
  const char* what = dropped ? "drop" : "pick";
  const std::vector<std::string> order_of = OrdersOfWaypoints(a);
  const auto& w = a.plan.waypoints;
  std::size_t stop = static_cast<std::size_t>(-1);
  bool planned = false;
  for (std::size_t i = 0; i < w.size(); ++i) {
    if (order_of[i] != order_id || w[i].action != action) continue;
    planned = true;
    if (static_cast<std::uint64_t>(w[i].seq) <= last_reached) stop = i;
  }
  if (!planned) return No("its plan has no " + std::string(what) + " of order " + order_id);
  if (stop == static_cast<std::size_t>(-1)) {
    ReportVerdict v = No("it has not reached the " + std::string(what) + " of order " + order_id +
                         " (last waypoint reached " + std::to_string(last_reached) + ")");
    v.later = true;
    return v;
  }
  const double off = robot_xy.allFinite() ? (robot_xy - w[stop].xy).norm() : -1.0;
  if (off < 0.0 || off > tolerance) {
    return No("it was last seen " + (off < 0.0 ? std::string("nowhere") : Metres(off)) + " from the " + what +
              " of order " + order_id + " (tolerance " + Metres(tolerance) + ")");
  }
  return {true, false, stop, {}};
}

}  // namespace dispatch::engine
