// DispatchCore: operators' commands on robots (issue 18 §4, robot_commands.h): pause and
// resume, out of service and back, clear off the floor, send to a station.
#include "engine/dispatch/dispatch_core.h"

namespace dispatch::engine {

Result<Change> DispatchCore::PlanCommand(const OperatorCommand& command, double now) {
  const BookRobot* r = robot(command.robot);
  if (!r) return NotFound("no robot '" + command.robot + "'");
  const std::string& id = command.robot;
  const std::string by = command.by.empty() ? "an operator" : command.by;
  OperatorMarks marks = r->marks;
  Change c;
  c.time = now;
  switch (command.kind) {
    case RobotCommandKind::kPause:
      if (!gate_) return Error{ErrorCode::kFailedPrecondition, "pausing robots needs traffic control (it holds them)"};
      marks.paused_by = by;
      break;
    case RobotCommandKind::kResume: marks.paused_by.clear(); break;
    case RobotCommandKind::kTakeOutOfService:
      marks.out_of_service_by = by;
      c = PlanLoss(id, "robot " + id + " taken out of service by " + by, now);
      break;
    case RobotCommandKind::kReturnToService: marks.out_of_service_by.clear(); break;
    case RobotCommandKind::kClear:
      if (r->connected) {
        return Error{ErrorCode::kFailedPrecondition,
                     "robot '" + id + "' is connected: only an offline robot is cleared off the floor (take it out "
                     "of service instead)"};
      }
      marks.off_floor = true;
      c = PlanLoss(id, "robot " + id + " cleared off the floor by " + by, now);
      break;
    case RobotCommandKind::kSend: {
      Result<Change> sent = PlanTrip(*r, command.to, now);
      if (!sent.ok()) return sent.error();
      c = std::move(*sent);
      break;
    }
  }
  c.marks[id] = std::move(marks);
  return c;
}

Result<Change> DispatchCore::PlanTrip(const BookRobot& r, PointId to, double now) const {
  const std::string& id = r.robot.id;
  if (to < 0 || static_cast<std::size_t>(to) >= map_->points().size()) {
    return NotFound("no point " + std::to_string(to) + " on the map");
  }
  const std::string where = "'" + map_->point(to).name + "'";
  auto busy = [&](const std::string& why) {
    return Error{ErrorCode::kFailedPrecondition, "robot '" + id + "' cannot be sent to " + where + ": " + why};
  };
  if (!r.connected) return busy("it is not connected");
  if (r.robot.current_point == kNoPoint) return busy("it is not on a map point");
  if (r.robot.state == RobotState::kFault) return busy("it is in fault");
  if (!r.marks.out_of_service_by.empty()) return busy("it is out of service");
  if (!r.marks.paused_by.empty()) return busy("it is paused");
  if (r.has_assignment && !r.assignment.order_ids.empty()) return busy("it serves orders");
  if (gate_ && !gate_->Available(id)) return busy("it is still leaving a formation's drop");
  for (const auto& [other_id, other] : robots_) {
    if (other_id == id) continue;
    const bool there = other.robot.current_point == to && !other.marks.off_floor;
    const bool going = OnTrip(other) && other.assignment.plan.waypoints.back().point == to;
    if (there || going) return busy("robot '" + other_id + "' " + (there ? "stands there" : "is sent there"));
  }
  Change c;
  c.time = now;
  const PointId start = StartOf(r);
  if (start == to) return c;  // there already (or arriving): nothing to drive
  const PointKind kind = map_->point(to).kind;
  const WaypointAction action = kind == PointKind::kCharge ? WaypointAction::kCharge : WaypointAction::kPark;
  Result<Plan> trip = BuildTrip(*map_, *routes_, start, now, r.robot.max_speed, to, action);
  if (!trip.ok()) return Error{trip.error().code, "robot '" + id + "' to " + where + ": " + trip.error().message};
  Assignment a = r.has_assignment ? r.assignment : Assignment{};
  std::uint64_t next = NextSequence(a);
  a.robot_id = id;
  a.plan_id += 1;
  a.order_ids.clear();
  a.plan.robot_id = id;
  a.plan.waypoints = std::move(trip->waypoints);
  for (Waypoint& w : a.plan.waypoints) w.seq = static_cast<int>(next++);
  a.released_up_to = static_cast<std::int64_t>(next) - 1;
  a.updated_time = now;
  c.plans.emplace(id, std::move(a));
  c.sends.push_back({id, PlanSend::Kind::kFull, 0, {}, {}});
  return c;
}

PointId DispatchCore::TripTo(const std::string& id) const {
  const BookRobot* r = robot(id);
  return r && OnTrip(*r) ? r->assignment.plan.waypoints.back().point : kNoPoint;
}

bool DispatchCore::OnTrip(const BookRobot& r) const {
  if (!r.has_assignment || !r.assignment.order_ids.empty() || r.assignment.plan.waypoints.empty()) return false;
  const Waypoint& last = r.assignment.plan.waypoints.back();
  return (last.action == WaypointAction::kPark || last.action == WaypointAction::kCharge) &&
         static_cast<std::uint64_t>(last.seq) > r.progress.last_reached;
}

}  // namespace dispatch::engine
