// 3-robot virtual-structure formations (Chu2024 §3.2, eq. (9); SPEC §3.3).
//
// The formation is a rigid equilateral triangle with side `side` (default 0.4 m, one robot
// diameter) around a virtual centre (x_vs, y_vs). Member i sits at distance
// D_f = side / sqrt(3) from the centre, at angle theta_i = heading + base_angle + i * 2*pi/3
// (eq. (9)); with base_angle = 0 member 0 is the front vertex, pointing along the heading of
// travel, and members 1 and 2 are the rear-left and rear-right vertices.
//
// Plans: each member drives its own Floyd route to the first pick point, then to its slot
// around it, and waits; the formation departs at the rendezvous time T_r, when the slowest
// member is in its slot. The centre then follows one route (BuildPlan) through the picks to
// the drop, and member i's waypoints are the centre's plus its offset rotated with the
// heading of the current route segment. Where the route turns, the structure rotates in
// place about the centre (after any work there), in steps of at most `max_rotation_step`
// (intermediate waypoints, so that straight-line interpolation between them stays close to
// the circle of radius D_f); a rotation by dtheta takes D_f * |dtheta| / v seconds. All
// members therefore share every ETA from T_r on. Waypoint `point` is the centre's point.
//
// Pure functions; thread-safe.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <numbers>
#include <vector>

#include "engine/common/result.h"
#include "engine/fleet/order.h"
#include "engine/fleet/plan.h"
#include "engine/map/warehouse_map.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine {

struct FormationOptions {
  double side = 0.4;                                // triangle side, m (> 0)
  double base_angle = 0.0;                          // radians added to every theta_i
  double max_rotation_step = std::numbers::pi / 4;  // radians (> 0)
};

using FormationOffsetArray = std::array<Eigen::Vector2d, kFormationTeamSize>;

// D_f of eq. (9): distance of every member from the centre.
double FormationRadius(const FormationOptions& options = {});

// Member offsets from the centre for a structure heading `heading` (eq. (9)):
// D_f * (cos theta_i, sin theta_i), via Eigen::Rotation2Dd.
FormationOffsetArray FormationOffsets(double heading, const FormationOptions& options = {});

// The structure heading at which member `member` is `offset` from the centre (eq. (9) solved
// for the heading; not wrapped).
double FormationHeadingOfSlot(const Eigen::Vector2d& offset, int member, const FormationOptions& options = {});

// Wraps an angle to (-pi, pi].
double WrapAngle(double a);

// A turn in place about the centre by `delta` radians (wrapped): `steps` steps of at most
// max_rotation_step each, each taking `step_time` s, the members' arc (D_f * angle) at
// `speed`. steps = 0 for no turn.
struct FormationTurn {
  int steps = 0;
  double step_time = 0.0;
};
FormationTurn PlanFormationTurn(double delta, double speed, const FormationOptions& options = {});

struct FormationPlans {
  Plan centre;                   // the virtual centre's plan, from T_r on
  std::vector<double> headings;  // structure heading at each centre waypoint
  std::vector<Plan> members;     // one per member, in the order of member_starts
  // Index in members[i].waypoints of the first formation waypoint (the pick at the first
  // pick point, eta = T_r); from there on members[i].waypoints[formation_start[i] + k]
  // corresponds to centre.waypoints[k].
  std::vector<std::size_t> formation_start;
  double rendezvous_time = 0.0;  // T_r
};

// Errors: kInvalidArgument (member_starts.size() != 3, bad speed / options / task),
// kNotFound (unknown point ids), kUnreachable (a member cannot reach the first pick, or the
// centre cannot follow the task; names both points).
Result<FormationPlans> BuildFormationPlans(const WarehouseMap& map, const RouteTable& routes,
                                           const std::vector<PointId>& member_starts,
                                           double start_time, double speed,
                                           const PlanTask& task,
                                           const FormationOptions& options = {});

}  // namespace dispatch::engine
