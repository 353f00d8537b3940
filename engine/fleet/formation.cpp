#include "engine/fleet/formation.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <string>

namespace dispatch::engine {
namespace {

// A member's own leg from `start` to the first pick point: waypoint 0 at `start`, every
// route point after it as a move. Returns the arrival time at the pick point.
Result<double> AppendRendezvousLeg(const WarehouseMap& map, const RouteTable& routes,
                                   PointId start, PointId target, double start_time,
                                   double speed, Plan& plan) {
  Result<Route> route = routes.Path(start, target);
  if (!route.ok()) return route.error();
  double time = start_time;
  auto append = [&](PointId p) {
    Waypoint w;
    w.seq = static_cast<int>(plan.waypoints.size());
    w.point = p;
    w.xy = map.point(p).position;
    w.eta = time;
    plan.waypoints.push_back(w);
  };
  append(start);
  for (std::size_t i = 0; i < route->arcs.size(); ++i) {
    const Arc& arc = map.arc(route->arcs[i]);
    time += arc.length / (arc.max_speed > 0.0 ? std::min(speed, arc.max_speed) : speed);
    append(route->points[i + 1]);
  }
  return time;
}

}  // namespace

double FormationRadius(const FormationOptions& options) { return options.side / std::sqrt(3.0); }

FormationOffsetArray FormationOffsets(double heading, const FormationOptions& options) {
  const double d_f = FormationRadius(options);
  FormationOffsetArray offsets;
  for (int i = 0; i < kFormationTeamSize; ++i) {
    // Chu2024 eq. (9): theta_i = heading + base + i * 2 pi / 3, |offset| = D_f.
    const double theta = heading + options.base_angle + i * 2.0 * std::numbers::pi / 3.0;
    offsets[static_cast<std::size_t>(i)] = Eigen::Rotation2Dd(theta) * Eigen::Vector2d(d_f, 0.0);
  }
  return offsets;
}

double FormationHeadingOfSlot(const Eigen::Vector2d& offset, int member, const FormationOptions& options) {
  const Eigen::Vector2d base = FormationOffsets(0.0, options)[static_cast<std::size_t>(member)];
  return std::atan2(offset.y(), offset.x()) - std::atan2(base.y(), base.x());
}

double WrapAngle(double a) {
  a = std::remainder(a, 2.0 * std::numbers::pi);
  return a <= -std::numbers::pi ? a + 2.0 * std::numbers::pi : a;
}

FormationTurn PlanFormationTurn(double delta, double speed, const FormationOptions& options) {
  const double angle = std::abs(WrapAngle(delta));
  if (angle <= 1e-9) return {};
  FormationTurn turn;
  turn.steps = std::max(1, static_cast<int>(std::ceil(angle / options.max_rotation_step - 1e-9)));
  turn.step_time = FormationRadius(options) * angle / turn.steps / speed;
  return turn;
}

Result<FormationPlans> BuildFormationPlans(const WarehouseMap& map, const RouteTable& routes,
                                           const std::vector<PointId>& member_starts,
                                           double start_time, double speed,
                                           const PlanTask& task,
                                           const FormationOptions& options) {
  if (member_starts.size() != static_cast<std::size_t>(kFormationTeamSize)) {
    return InvalidArgument("a formation needs " + std::to_string(kFormationTeamSize) +
                           " members, got " + std::to_string(member_starts.size()));
  }
  if (!std::isfinite(options.side) || options.side <= 0.0) {
    return InvalidArgument("formation side must be > 0 m, got " + std::to_string(options.side));
  }
  if (!std::isfinite(options.max_rotation_step) || options.max_rotation_step <= 0.0) {
    return InvalidArgument("formation max rotation step must be > 0 rad");
  }
  if (!std::isfinite(options.base_angle)) return InvalidArgument("formation base angle not finite");
  if (task.picks.empty()) return InvalidArgument("formation task: no pick points");
  // The centre's route through the task, timed from 0; validates speed, points and task.
  Result<Plan> centre_route = BuildPlan(map, routes, task.picks[0], 0.0, speed, {task});
  if (!centre_route.ok()) return Error{centre_route.error().code,
                                       "formation centre: " + centre_route.error().message};
  // Drop BuildPlan's start waypoint: it coincides with the pick at the first pick point.
  std::vector<Waypoint> track(centre_route->waypoints.begin() + 1, centre_route->waypoints.end());

  // Heading of the first non-degenerate segment: the structure's heading at the rendezvous.
  double heading = 0.0;
  for (std::size_t k = 0; k + 1 < track.size(); ++k) {
    const Eigen::Vector2d d = track[k + 1].xy - track[k].xy;
    if (d.norm() > 1e-9) {
      heading = std::atan2(d.y(), d.x());
      break;
    }
  }
  const double initial_heading = heading;

  // Rendezvous legs: route to the first pick point, then the slot around it.
  const double d_f = FormationRadius(options);
  const PointId first_pick = task.picks[0];
  const Eigen::Vector2d rendezvous_xy = map.point(first_pick).position;
  const FormationOffsetArray slots = FormationOffsets(initial_heading, options);
  FormationPlans result;
  result.members.resize(member_starts.size());
  double rendezvous = start_time;
  for (std::size_t i = 0; i < member_starts.size(); ++i) {
    Plan& plan = result.members[i];
    Result<double> arrival = AppendRendezvousLeg(map, routes, member_starts[i], first_pick,
                                                 start_time, speed, plan);
    if (!arrival.ok()) {
      return Error{arrival.error().code,
                   "formation member " + std::to_string(i) + ": " + arrival.error().message};
    }
    Waypoint slot;
    slot.seq = static_cast<int>(plan.waypoints.size());
    slot.point = first_pick;
    slot.xy = rendezvous_xy + slots[i];
    slot.eta = *arrival + d_f / speed;
    slot.action = WaypointAction::kWait;
    plan.waypoints.push_back(slot);
    rendezvous = std::max(rendezvous, slot.eta);
  }
  result.rendezvous_time = rendezvous;
  for (Plan& plan : result.members) {
    Waypoint& slot = plan.waypoints.back();
    slot.dwell = rendezvous - slot.eta;  // everyone waits for the slowest member
  }

  // The centre's timed track from T_r, with in-place rotations at turns.
  double shift = rendezvous;
  auto emit = [&](Waypoint w, double h) {
    w.seq = static_cast<int>(result.centre.waypoints.size());
    result.centre.waypoints.push_back(w);
    result.headings.push_back(h);
  };
  for (std::size_t k = 0; k < track.size(); ++k) {
    Waypoint w = track[k];
    w.eta += shift;
    emit(w, heading);
    if (k + 1 == track.size()) break;
    const Eigen::Vector2d d = track[k + 1].xy - track[k].xy;
    if (d.norm() <= 1e-9) continue;
    const double delta = WrapAngle(std::atan2(d.y(), d.x()) - heading);
    const auto [steps, step_time] = PlanFormationTurn(delta, speed, options);
    if (steps == 0) continue;
    Waypoint turn;
    turn.point = w.point;
    turn.xy = w.xy;
    turn.action = WaypointAction::kMove;
    double t = w.departure();
    for (int s = 1; s <= steps; ++s) {
      t += step_time;
      turn.eta = t;
      emit(turn, heading + delta * s / steps);
    }
    shift += d_f * std::abs(delta) / speed;
    heading = WrapAngle(heading + delta);
  }

  // Members: the centre's waypoints plus their rigid offsets.
  for (std::size_t i = 0; i < result.members.size(); ++i) {
    Plan& plan = result.members[i];
    result.formation_start.push_back(plan.waypoints.size());
    for (std::size_t k = 0; k < result.centre.waypoints.size(); ++k) {
      Waypoint w = result.centre.waypoints[k];
      w.seq = static_cast<int>(plan.waypoints.size());
      w.xy += FormationOffsets(result.headings[k], options)[i];
      plan.waypoints.push_back(w);
    }
  }
  return result;
}

}  // namespace dispatch::engine
