// Assignment: a robot's current plan in the dispatch book, and the one set of rules for its
// shape (issue 15 §1: one model of what a plan means, for the service and the simulator).
//
// Shape. plan.waypoints[0] anchors the plan where the robot stood when it was made (or where
// its previous order ended); then one segment per order in order_ids, each up to and including
// its drop waypoint: segment k serves order_ids[k]. Waypoints carry the robot's life-long
// sequence numbers (Waypoint::seq): they only grow over the robot's life, across plans, so a
// robot's report "reached waypoint s" is never ambiguous; released_up_to keeps the highest
// sequence ever issued (never lowered, also when the plan is cut).
//
// Values and free functions only; not thread-safe to mutate concurrently.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "engine/fleet/plan.h"
#include "engine/traffic/traffic_gate.h"

namespace dispatch::engine {

struct Assignment {
  std::string robot_id;
  std::uint64_t plan_id = 0;           // increasing per robot
  std::vector<std::string> order_ids;  // in execution order
  Plan plan;                           // plan.robot_id == robot_id
  std::int64_t released_up_to = -1;    // highest waypoint seq ever issued; -1 = none
  double updated_time = 0.0;
};

// Index of the first waypoint of the k-th order segment (k = order_ids.size(): the end).
std::size_t SegmentStart(const Assignment& a, std::size_t k);
// SegmentStart for every k = 0 .. order_ids.size(), in one pass.
std::vector<std::size_t> SegmentStarts(const Assignment& a);
// Per waypoint, the order it serves ("" for the anchor and for waypoints past the last drop).
std::vector<std::string> OrdersOfWaypoints(const Assignment& a);
// The order waypoint `index` serves (OrdersOfWaypoints for one waypoint). O(index).
std::string OrderOfWaypoint(const Assignment& a, std::size_t index);
// A waypoint whose order is known: a waypoint's order never changes while it stays in the plan
// (sequences are never reused; a plan only loses its first order's waypoints, is cut after a
// segment or is rewritten after the waypoint the robot reached), so a robot's next arrivals
// are found from it instead of from the plan's start.
struct OrderCursor {
  std::int64_t seq = -1;  // -1: none yet
  std::string order;
};
// OrderOfWaypoint(a, index), counting the drops from the cursor's waypoint when it is still in
// the plan before `index` and its order is in order_ids once; the cursor moves to `index`.
// O(waypoints since the cursor) for arrivals in plan order.
std::string OrderOfWaypoint(const Assignment& a, std::size_t index, OrderCursor& cursor);
// The first sequence never issued to the robot: above released_up_to and every waypoint.
std::uint64_t NextSequence(const Assignment& a);
// The highest sequence ever numbered for the robot (-1: none): a robot cannot have passed a
// waypoint beyond it.
std::int64_t HighestNumbered(const Assignment& a);
// The waypoint with sequence `seq` in the current plan (index), or npos.
std::size_t FindWaypoint(const Assignment& a, std::uint64_t seq);

// Removes `order_id` and every later order from the plan (the anchor stays); returns the later
// ones. Nothing changes (and {} is returned) when the plan does not hold the order.
std::vector<std::string> CutPlan(Assignment& a, const std::string& order_id);
// Drops the finished first order (the waypoints up to its drop, which becomes the new anchor);
// false when `order_id` is not the plan's first order.
bool TrimDone(Assignment& a, const std::string& order_id);

// Appends an awarded order's waypoints, numbered from NextSequence. `restart`: the robot had
// no orders, so the plan starts anew (plan_id + 1, the segment's first waypoint is the anchor).
// Otherwise the segment, planned from a re-timed copy of the queue whose last departure was
// `after_departure`, is shifted so that it never starts before the stored plan ends. Returns
// the first new sequence.
std::uint64_t AppendOrder(Assignment& a, const std::string& order_id,
                          const std::vector<Waypoint>& segment, double after_departure, bool restart,
                          double now);

// The plan as the traffic gate takes it; `teams` names the formation orders' members.
GatePlan ToGatePlan(const Assignment& a, std::map<std::string, std::vector<std::string>> teams);

}  // namespace dispatch::engine
