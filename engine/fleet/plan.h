// Timed plans (SPEC §3.4): the waypoints a robot follows, each with its ETA and action.
// Plans are what the dispatcher streams to robots and what traffic prediction reads.
//
// ETA convention: a waypoint's `eta` is the time the robot ARRIVES there. At a pick or drop
// waypoint the robot then works for `dwell` seconds (t_w) standing still and departs at
// eta + dwell; so the next waypoint's eta already includes the work time. Move waypoints have
// dwell 0. Between the departure from one waypoint and the arrival at the next the robot
// moves in a straight line at constant speed.
//
// Work time counting (Chu2024 eq. (3): T_w = n_c * t_w): n_c counts the paper's task points
// ("任务点"), which §4.2 defines as an order's pick points ("任务点为订单取货地点"); the drop is
// its target point ("目标点"), where §2.2 has the robot drive, not work. So a task with k picks
// has n_c = k and the robot works t_w at every pick. At the drop it works the task's own
// `drop_time` (0 in the seed's model; AllocationConfig::drop_time sets it for the product).
//
// Invariants of a Plan from BuildPlan: waypoints non-empty, seq = 0, 1, 2, ...; etas
// non-decreasing; eta[i+1] >= eta[i] + dwell[i]. Plain values; safe to share once built.
// BuildPlan is pure (reads the map and route table only).
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "engine/common/result.h"
#include "engine/map/warehouse_map.h"
#include "engine/motion/motion_path.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine {

enum class WaypointAction { kMove, kPick, kDrop, kWait, kPark, kCharge };

// "move", "pick", "drop", "wait", "park", "charge".
const char* WaypointActionName(WaypointAction action);
std::optional<WaypointAction> ParseWaypointAction(std::string_view name);

struct Waypoint {
  int seq = 0;
  PointId point = kNoPoint;
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();  // where the robot is (a formation member's
                                                 // slot may be off the point itself)
  double eta = 0.0;    // arrival time, seconds
  WaypointAction action = WaypointAction::kMove;
  double dwell = 0.0;  // seconds standing still after arrival (t_w at pick/drop), >= 0
  // A four-wheel-steer robot's pose and motion inside a free-space region
  // (engine/motion/free_space_plan.h): the heading it holds at this waypoint (radians,
  // counter-clockwise from +x) and how it gets here from the previous waypoint. Unset on the
  // road graph, where a robot drives along each arc.
  std::optional<double> heading;
  std::optional<MotionMode> mode;

  double departure() const { return eta + dwell; }
};

// Index of the waypoint numbered `seq` in `w`, or npos. Plans are numbered in ascending order
// (a plan is built 0, 1, 2, ... and re-plans append higher numbers), mostly without gaps:
// O(1) then, O(log n) with gaps, a scan for a plan out of order.
std::size_t FindSequence(const std::vector<Waypoint>& w, std::uint64_t seq);

struct Plan {
  std::string robot_id;
  std::vector<Waypoint> waypoints;

  // Position at time t: the first waypoint before the plan starts, the last after it ends,
  // still during a dwell, linear between departure and the next arrival otherwise.
  // Precondition: waypoints non-empty (else throws std::logic_error). O(log n).
  Eigen::Vector2d PositionAt(double t) const;
  double start_time() const;  // first eta (precondition as above)
  double end_time() const;    // last departure (precondition as above)
};

// One task for one robot: visit the picks in order, t_w at each, then the drop, drop_time
// there (see above).
struct PlanTask {
  std::vector<PointId> picks;
  PointId drop = kNoPoint;
  double work_time = 0.0;  // t_w, seconds at each pick, >= 0
  double drop_time = 0.0;  // seconds at the drop, >= 0
  // Order::stop_headings: radians by stop index (picks in order, then the drop). Only a
  // four-wheel-steer robot refined through a free-space region can serve a task with one
  // (FleetState::CanServe).
  std::map<std::size_t, double> stop_headings{};
};

// n_c of one task: its picks (Chu2024 eq. (3)).
int TaskPointCount(const PlanTask& task);
// T_w of one task: n_c * t_w (Chu2024 eq. (3)) + its drop_time.
double TaskWorkTime(const PlanTask& task);

// Builds the plan of one robot at `start` at `start_time` serving `tasks` in order at speed
// `speed` (m/s; an arc's own max_speed caps it where lower). Waypoint 0 is the start (move,
// eta = start_time); every point of the RouteTable's route between consecutive stops becomes
// a waypoint (move for passed points, pick/drop at the stops, with dwell = t_w), ETAs by
// arc length / speed plus `turn_time` seconds per 90 degrees of heading change between
// consecutive arcs of the plan (Wang2019's turning time t_c, spent standing before the next
// arc; the first arc's turn is not counted: a standing robot's heading is not known here).
// No tasks: just the start waypoint. robot_id is left empty.
// Errors: kInvalidArgument (speed <= 0, non-finite start time, a task without picks or with
// negative t_w), kNotFound (unknown point id), kUnreachable (names both points).
Result<Plan> BuildPlan(const WarehouseMap& map, const RouteTable& routes, PointId start,
                       double start_time, double speed, const std::vector<PlanTask>& tasks,
                       double turn_time = 0.0);

// The plan of one robot at `start` at `start_time` driving to `to` (an operator sending it to a
// station): as BuildPlan, the route's points as move waypoints, the last one `action` (e.g.
// park) with no dwell. `to` == `start`: the start waypoint alone, with `action`.
// Errors: as BuildPlan (kNotFound names the destination).
Result<Plan> BuildTrip(const WarehouseMap& map, const RouteTable& routes, PointId start, double start_time,
                       double speed, PointId to, WaypointAction action, double turn_time = 0.0);

}  // namespace dispatch::engine
