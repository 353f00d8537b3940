#include "engine/dispatch/assignment.h"

#include <algorithm>

namespace dispatch::engine {

std::size_t SegmentStart(const Assignment& a, std::size_t k) {
  if (k == 0) return 1;
  std::size_t drops = 0;
  const auto& w = a.plan.waypoints;
  for (std::size_t i = 1; i < w.size(); ++i) {
    if (w[i].action == WaypointAction::kDrop && ++drops == k) return i + 1;
  }
  return w.size();
}

std::vector<std::size_t> SegmentStarts(const Assignment& a) {
  const auto& w = a.plan.waypoints;
  std::vector<std::size_t> out{1};
  for (std::size_t i = 1; i < w.size() && out.size() <= a.order_ids.size(); ++i) {
    if (w[i].action == WaypointAction::kDrop) out.push_back(i + 1);
  }
  out.resize(a.order_ids.size() + 1, w.size());
  return out;
}

std::vector<std::string> OrdersOfWaypoints(const Assignment& a) {
  const auto& w = a.plan.waypoints;
  std::vector<std::string> out(w.size());
  std::size_t drops = 0;
  for (std::size_t i = 1; i < w.size() && drops < a.order_ids.size(); ++i) {
    out[i] = a.order_ids[drops];
    if (w[i].action == WaypointAction::kDrop) ++drops;
  }
  return out;
}

std::string OrderOfWaypoint(const Assignment& a, std::size_t index) {
  if (index == 0) return {};
  std::size_t drops = 0;
  const auto& w = a.plan.waypoints;
  for (std::size_t i = 1; i < index && i < w.size(); ++i) {
    if (w[i].action == WaypointAction::kDrop) ++drops;
  }
  return drops < a.order_ids.size() ? a.order_ids[drops] : std::string();
}

std::string OrderOfWaypoint(const Assignment& a, std::size_t index, OrderCursor& cursor) {
  const auto& w = a.plan.waypoints;
  std::string order;
  const std::size_t from =
      cursor.seq >= 0 && !cursor.order.empty() ? FindWaypoint(a, static_cast<std::uint64_t>(cursor.seq)) : 0;
  const auto ids = a.order_ids.begin(), end = a.order_ids.end();
  const auto at = from >= 1 && from <= index && index < w.size() ? std::find(ids, end, cursor.order) : end;
  if (at != end && std::find(at + 1, end, cursor.order) == end) {
    // The cursor's waypoint serves *at: every drop from it up to `index` moves one order on.
    auto k = static_cast<std::size_t>(at - ids);
    for (std::size_t i = from; i < index; ++i) {
      if (w[i].action == WaypointAction::kDrop) ++k;
    }
    if (k < a.order_ids.size()) order = a.order_ids[k];
  } else {
    order = OrderOfWaypoint(a, index);
  }
  if (index < w.size() && !order.empty()) {
    cursor.seq = w[index].seq;
    cursor.order = order;
  }
  return order;
}

std::uint64_t NextSequence(const Assignment& a) {
  return static_cast<std::uint64_t>(HighestNumbered(a) + 1);
}

std::int64_t HighestNumbered(const Assignment& a) {
  std::int64_t top = std::max<std::int64_t>(a.released_up_to, -1);
  if (!a.plan.waypoints.empty()) top = std::max<std::int64_t>(top, a.plan.waypoints.back().seq);
  return top;
}

std::size_t FindWaypoint(const Assignment& a, std::uint64_t seq) {
  return FindSequence(a.plan.waypoints, seq);
}

std::vector<std::string> CutPlan(Assignment& a, const std::string& order_id) {
  auto it = std::find(a.order_ids.begin(), a.order_ids.end(), order_id);
  if (it == a.order_ids.end()) return {};
  const auto k = static_cast<std::size_t>(it - a.order_ids.begin());
  a.plan.waypoints.resize(std::min(a.plan.waypoints.size(), std::max<std::size_t>(1, SegmentStart(a, k))));
  std::vector<std::string> later(it + 1, a.order_ids.end());
  a.order_ids.resize(k);
  return later;
}

bool TrimDone(Assignment& a, const std::string& order_id) {
  if (a.order_ids.empty() || a.order_ids.front() != order_id) return false;
  auto& w = a.plan.waypoints;
  if (!w.empty()) {
    const std::size_t drop = SegmentStart(a, 1) - 1;  // the first order's drop waypoint
    w.erase(w.begin(), w.begin() + static_cast<std::ptrdiff_t>(std::min(drop, w.size() - 1)));
  }
  a.order_ids.erase(a.order_ids.begin());
  return true;
}

std::uint64_t AppendOrder(Assignment& a, const std::string& order_id,
                          const std::vector<Waypoint>& segment, double after_departure, bool restart,
                          double now) {
  std::uint64_t next = NextSequence(a);
  const std::uint64_t first = next;
  const bool fresh = restart || a.order_ids.empty();
  if (fresh) {
    a.plan_id += 1;
    a.plan.robot_id = a.robot_id;
    a.plan.waypoints.clear();
    a.order_ids.clear();
  }
  // The segment was planned on a queue re-timed from the round's start (ReplayQueue): it
  // never starts before the robot's stored plan actually ends.
  const double shift =
      fresh || segment.empty() || a.plan.waypoints.empty() ? 0.0 : std::max(0.0, a.plan.end_time() - after_departure);
  for (Waypoint wp : segment) {
    wp.seq = static_cast<int>(next++);
    wp.eta += shift;
    a.plan.waypoints.push_back(wp);
  }
  a.order_ids.push_back(order_id);
  a.released_up_to = static_cast<std::int64_t>(next) - 1;
  a.updated_time = now;
  return first;
}

GatePlan ToGatePlan(const Assignment& a, std::map<std::string, std::vector<std::string>> teams) {
  GatePlan g;
  g.waypoints = a.plan.waypoints;
  g.order_of = OrdersOfWaypoints(a);
  g.teams = std::move(teams);
  g.next_sequence = NextSequence(a);
  return g;
}

}  // namespace dispatch::engine
