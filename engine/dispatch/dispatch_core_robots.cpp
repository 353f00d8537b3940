// DispatchCore: robots (connect, reports, arrivals, picks and drops) and traffic control (the
// gate's releases, holds, re-plans and blocked robots).
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "engine/dispatch/dispatch_core.h"
#include "engine/dispatch/robot_intake.h"

namespace dispatch::engine {

void DispatchCore::RestoreRobot(Robot robot, std::optional<Assignment> plan, bool place, OperatorMarks marks) {
  const std::string id = robot.id;
  BookRobot& r = Book(id);
  r.robot = std::move(robot);
  r.robot.state = RobotState::kOffline;
  r.connected = false;
  r.marks = std::move(marks);
  if (gate_ && !r.marks.HeldFor().empty()) gate_->SetPaused(id, r.marks.HeldFor());
  if (plan) {
    r.assignment = std::move(*plan);
    r.round_copy.reset();
    r.has_assignment = true;
    r.robot.task_queue = r.assignment.order_ids;
  }
  if (place) Place(id);
}

void DispatchCore::Place(const std::string& id) {
  const BookRobot* r = robot(id);
  if (!r || !gate_ || r->marks.off_floor) return;
  const PointId p = r->robot.current_point;
  if (p == kNoPoint || static_cast<std::size_t>(p) >= map_->points().size()) return;
  gate_->Connect(id, map_->point(p).position, p);
  gate_->Disconnect(id);
}

std::vector<RobotCommand> DispatchCore::Connect(Robot robot, double now) {
  const std::string id = robot.id;
  BookRobot& r = Book(id);
  r.robot = std::move(robot);
  r.robot.task_queue = r.has_assignment ? r.assignment.order_ids : std::vector<std::string>{};
  r.connected = true;
  r.marks.off_floor = false;  // a Hello puts a cleared robot back on the floor
  const bool was_blocked = r.blocked_at >= 0.0;
  r.blocked_at = -1.0;  // a Hello ends a block's fault (Recover drops it from blocked_)
  allocation_due_ = true;
  if (gate_) {
    gate_->Connect(id, r.robot.pose.position, r.robot.current_point);
    if (was_blocked) gate_->Unblock(id, now);
    SyncGate(r);
  }
  if (!r.has_assignment || (r.assignment.order_ids.empty() && !OnTrip(r))) return {};
  // Resume: the robot gets its whole current plan again (it skips waypoints it has passed).
  return {{id, PlanMessage(r, true, 0)}};
}

void DispatchCore::Disconnect(const std::string& id) {
  BookRobot* r = FindRobot(id);
  if (!r) return;
  r->connected = false;
  r->robot.state = RobotState::kOffline;
  if (gate_) gate_->Disconnect(id);
}

ReportOutcome DispatchCore::Report(const std::string& id, const Pose& pose, std::optional<int> arc_id,
                                   std::optional<RobotState> state, std::optional<double> battery,
                                   std::uint64_t claimed, double now) {
  ReportOutcome out;
  BookRobot* r = FindRobot(id);
  // A pose off the floor (NaN, 1e300, a wrong frame) is not news about the robot: it would
  // leave it at no map point and out of every auction. Ignored, like a bad battery value.
  if (!r || !OnFloor(*map_, pose.position, options_.robot_snap_tolerance) || !std::isfinite(pose.heading)) {
    out.taken = false;
    return out;
  }
  r->robot.pose = pose;
  if (arc_id && *arc_id >= 0 && static_cast<std::size_t>(*arc_id) < map_->arcs().size()) {
    r->robot.current_point = map_->arc(*arc_id).to;
  } else {
    r->robot.current_point = map_->NearestPointFrom(pose.position, r->robot.current_point);
  }
  if (state && *state != RobotState::kOffline && r->robot.state != RobotState::kFault) r->robot.state = *state;
  if (battery && *battery >= 0.0 && *battery <= 1.0) r->robot.battery = *battery;
  // A waypoint beyond the highest ever numbered for this robot was never sent, so it cannot
  // have been passed: such a claim is ignored (the gate would otherwise take the robot to be
  // at its plan's end and disregard its real progress from then on).
  std::uint64_t passed = 0;
  out.retry = TakeStateProgress(r->progress, r->assignment, claimed, &passed);
  if (GateBot* g = GateEntry(*r, id)) gate_->Report(*g, pose.position, passed, now);
  return out;
}

ReportOutcome DispatchCore::Reached(const std::string& id, std::uint64_t seq, const std::optional<Pose>& pose,
                                    double now) {
  ReportOutcome out;
  BookRobot* r = FindRobot(id);
  if (!r) {
    out.taken = false;
    out.why = "unknown robot";
    return out;
  }
  const std::optional<Eigen::Vector2d> xy = pose ? std::optional<Eigen::Vector2d>(pose->position) : std::nullopt;
  GateBot* g = GateEntry(*r, id);
  const std::uint64_t released = g ? gate_->ReleasedUpTo(*g) : ReleasedUpTo(id);
  Arrival arrival = TakeArrival(r->progress, r->assignment, seq, released, xy, options_.robot_snap_tolerance);
  if (!arrival.verdict.taken) {
    out.taken = false;
    out.why = arrival.verdict.why;
    return out;
  }
  const std::size_t i = arrival.verdict.index;
  const Waypoint& w = r->assignment.plan.waypoints[i];
  r->robot.current_point = w.point;
  if (auto o = orders_.find(arrival.order); o != orders_.end()) o->second.distance += arrival.driven;
  if (arrival.xy) {
    r->robot.pose.position = *arrival.xy;
    if (pose && std::isfinite(pose->heading)) r->robot.pose.heading = pose->heading;
  }
  if (g) gate_->Reached(*g, seq, now, arrival.xy);
  if (w.action == WaypointAction::kPick) {
    const std::string order_id = arrival.fresh ? arrival.order : OrderOfWaypoint(r->assignment, i);
    if (auto line = StartLine(order_id, id + " reached pick '" + map_->point(w.point).name + "'")) {
      out.change = Change{now, {std::move(*line)}, {}, {}, {}, 0, {}};
    }
  }
  out.retry = std::move(arrival.retry);
  return out;
}

TaskOutcome DispatchCore::PlanTask(const std::string& id, const TaskReport& report, double now) {
  TaskOutcome out;
  BookRobot* r = FindRobot(id);
  const BookOrder* o = order(report.order_id);
  if (!r || !o) return out;  // late or repeated (finished orders leave the book)
  const std::vector<std::string>& team = o->robots;
  if (std::find(team.begin(), team.end(), id) == team.end()) return out;
  if (report.dropped && o->dropped_by.count(id)) return out;  // repeated
  out.what = std::string(report.dropped ? "dropped" : "picked") + " for order " + report.order_id;
  const TaskVerdict verdict =
      TakeTaskReport(r->progress, r->assignment, report, r->robot.pose.position, options_.robot_snap_tolerance);
  if (verdict.decision != TaskDecision::kTaken) {
    // Waiting: e.g. a drop repeated after a restart before the robot's first progress report.
    out.kind = verdict.decision == TaskDecision::kWaiting ? TaskOutcome::Kind::kWaiting : TaskOutcome::Kind::kImplausible;
    out.why = verdict.why;
    out.overflowed = verdict.overflowed;
    return out;
  }
  // Where it did it: the stop of its plan (the point id it sent is not needed).
  const std::string where = "'" + map_->point(r->assignment.plan.waypoints[verdict.index].point).name + "'";
  const std::string detail = id + (report.dropped ? " dropped at " : " picked at ") + where;
  out.kind = TaskOutcome::Kind::kChange;
  Change& c = out.change;
  c.time = now;
  std::optional<OrderChange> start = StartLine(report.order_id, detail);
  if (start) c.orders.push_back(*start);
  if (!report.dropped) {
    if (!start) c.orders.push_back({report.order_id, std::nullopt, std::nullopt, detail, std::nullopt, OrderChange::kNoAward, {}});
    return out;
  }
  DropOutcome drop = PlanDrop(r->assignment, report.order_id, id, team, o->dropped_by);
  if (drop.trimmed) {
    drop.plan.updated_time = now;
    c.plans.emplace(id, std::move(drop.plan));
  }
  c.dropped_by[report.order_id] = std::move(drop.dropped_by);
  OrderChange line{report.order_id, std::nullopt, std::nullopt, detail, std::nullopt, OrderChange::kNoAward, {}};
  if (drop.complete) {
    line.to = OrderState::kCompleted;
    line.distance = o->distance;
  }
  c.orders.push_back(std::move(line));
  return out;
}

StepOutcome DispatchCore::Step(double now) {
  StepOutcome out;
  if (!gate_) return out;
  std::vector<GateEffect> effects = gate_->Step(now);
  if (gate_->LeavingEnded() != leaving_seen_) {  // members free to bid again
    leaving_seen_ = gate_->LeavingEnded();
    allocation_due_ = true;
  }
  for (GateEffect& e : effects) {
    BookRobot* r = FindRobot(e.robot);
    if (!r) continue;
    RobotMessage m;
    switch (e.kind) {
      case GateEffect::Kind::kRelease:
        m.released_up_to = e.release_up_to;
        if (e.resume) {
          m.kind = RobotMessage::Kind::kResume;
        } else {
          m.kind = RobotMessage::Kind::kGrant;
          if (e.intersection >= 0 && static_cast<std::size_t>(e.intersection) < map_->intersections().size()) {
            m.intersection_id = e.intersection;
            m.intersection_name = map_->intersections()[static_cast<std::size_t>(e.intersection)].name;
          }
          ++counts_.grants;
        }
        out.messages.push_back({e.robot, std::move(m)});
        break;
      case GateEffect::Kind::kHold:
        m.kind = RobotMessage::Kind::kHold;
        m.stop_at_sequence = e.hold_at;
        m.reason = e.reason;
        ++counts_.holds;
        out.messages.push_back({e.robot, std::move(m)});
        break;
      case GateEffect::Kind::kRewrite: {
        Assignment& a = r->assignment;
        if (a.robot_id.empty()) a.robot_id = a.plan.robot_id = e.robot;  // an idle robot sent aside
        a.plan.waypoints = std::move(e.waypoints);
        if (!a.plan.waypoints.empty()) a.released_up_to = std::max<std::int64_t>(a.released_up_to, a.plan.waypoints.back().seq);
        a.updated_time = now;
        r->round_copy.reset();
        r->has_assignment = true;
        ++counts_.replans;
        out.rewritten.push_back(a);
        out.messages.push_back({e.robot, PlanMessage(*r, false, e.from_sequence)});
        break;
      }
      case GateEffect::Kind::kBlocked:
        r->robot.state = RobotState::kFault;
        if (r->blocked_at < 0.0) blocked_.push_back(r);
        r->blocked_at = now;
        out.blocked.emplace_back(e.robot, e.reason);
        break;
    }
  }
  out.notes = gate_->TakeNotes();
  Recover(now, out);
  return out;
}

void DispatchCore::Recover(double now, StepOutcome& out) {
  if (options_.blocked_recovery <= 0.0) return;
  std::erase_if(blocked_, [&](BookRobot* r) {
    if (r->blocked_at < 0.0 || r->robot.state != RobotState::kFault) {  // said Hello again
      r->blocked_at = -1.0;
      return true;
    }
    // Its orders are given back first (the owner's PlanLoss); one still held waits for that.
    if (now - r->blocked_at < options_.blocked_recovery || (r->has_assignment && !r->assignment.order_ids.empty())) {
      return false;
    }
    r->robot.state = RobotState::kIdle;
    r->blocked_at = -1.0;
    gate_->Unblock(r->robot.id, now);
    allocation_due_ = true;
    out.recovered.push_back(r->robot.id);
    char note[160];
    std::snprintf(note, sizeof note, "robot %s back in service after %.0f s blocked", r->robot.id.c_str(),
                  options_.blocked_recovery);
    out.notes.emplace_back(note);
    return true;
  });
}

GateBot* DispatchCore::GateEntry(BookRobot& r, const std::string& id) {
  if (!r.gate_entry && gate_) r.gate_entry = gate_->Entry(id);
  return r.gate_entry;
}

void DispatchCore::SampleDistances(double now) {
  if (gate_) gate_->SampleDistances(now);
}

}  // namespace dispatch::engine
