#include "clients/sim_robot.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace dispatch::clients {
namespace {

constexpr double kArriveEps = 1e-9;
constexpr std::size_t kMaxFinishedDrops = 64;

Eigen::Vector2d Xy(const v1::TimedWaypoint& w) { return {w.x(), w.y()}; }

bool IsTask(const v1::TimedWaypoint& w) {
  return w.action() == v1::WAYPOINT_ACTION_PICK || w.action() == v1::WAYPOINT_ACTION_DROP;
}

v1::RobotMessage TaskEventFor(const v1::TimedWaypoint& w) {
  v1::RobotMessage m;
  v1::TaskEvent* e = m.mutable_task_event();
  e->set_order_id(w.order_id());
  e->set_type(w.action() == v1::WAYPOINT_ACTION_PICK ? v1::TASK_EVENT_TYPE_PICKED
                                                     : v1::TASK_EVENT_TYPE_DROPPED);
  e->set_point_id(w.point_id());
  e->set_waypoint_sequence(w.sequence());
  return m;
}

}  // namespace

SimRobot::SimRobot(std::string id, const Eigen::Vector2d& position, double speed)
    : id_(std::move(id)), position_(position), speed_(speed) {}

v1::RobotMessage SimRobot::Hello() const {
  v1::RobotMessage m;
  v1::Hello* h = m.mutable_hello();
  h->set_robot_id(id_);
  h->set_kind(kind_);
  h->mutable_pose()->set_x(position_.x());
  h->mutable_pose()->set_y(position_.y());
  h->mutable_pose()->set_theta(heading_);
  h->set_last_acked_sequence(last_applied_);
  h->set_max_speed(speed_);
  return m;
}

void SimRobot::AdoptWaypoints(const google::protobuf::RepeatedPtrField<v1::TimedWaypoint>& wps) {
  for (const v1::TimedWaypoint& w : wps) {
    // Waypoints already reached (a re-sent plan after a reconnect) are not driven again.
    if (w.sequence() <= last_reached_) continue;
    if (!waypoints_.empty() && w.sequence() <= waypoints_.back().wp.sequence()) continue;
    waypoints_.push_back({w, false});
    if (w.released()) released_up_to_ = std::max(released_up_to_, w.sequence());
  }
}

void SimRobot::RepeatFinishedDrops(
    const google::protobuf::RepeatedPtrField<v1::TimedWaypoint>& wps) {
  for (const v1::TimedWaypoint& w : wps) {
    if (w.action() != v1::WAYPOINT_ACTION_DROP || w.order_id().empty()) continue;
    for (const auto& [seq, order] : finished_drops_) {
      if (seq == w.sequence() && order == w.order_id()) repeats_.push_back(TaskEventFor(w));
    }
  }
}

bool SimRobot::Apply(const v1::ServerMessage& message, double now, std::optional<double>* released_after) {
  if (message.sequence() != 0 && message.sequence() <= last_applied_) return false;
  last_applied_ = std::max(last_applied_, message.sequence());
  const std::uint64_t horizon_before = released_up_to_;
  switch (message.body_case()) {
    case v1::ServerMessage::kAssignment: {
      const v1::Assignment& a = message.assignment();
      waypoints_.clear();
      RepeatFinishedDrops(a.waypoints());
      AdoptWaypoints(a.waypoints());
      released_up_to_ = std::max(released_up_to_, a.released_up_to_sequence());
      break;
    }
    case v1::ServerMessage::kPlanUpdate: {
      const v1::PlanUpdate& u = message.plan_update();
      while (!waypoints_.empty() && waypoints_.back().wp.sequence() >= u.from_sequence()) {
        waypoints_.pop_back();
      }
      RepeatFinishedDrops(u.waypoints());
      AdoptWaypoints(u.waypoints());
      released_up_to_ = std::max(released_up_to_, u.released_up_to_sequence());
      break;
    }
    case v1::ServerMessage::kGrant:
      released_up_to_ = std::max(released_up_to_, message.grant().release_up_to_sequence());
      break;
    case v1::ServerMessage::kHold:
      held_ = true;
      hold_at_ = message.hold().stop_at_sequence();
      break;
    case v1::ServerMessage::kResume:
      held_ = false;
      hold_at_ = 0;
      released_up_to_ = std::max(released_up_to_, message.resume().release_up_to_sequence());
      break;
    case v1::ServerMessage::kCancel: {
      const auto& ids = message.cancel().order_ids();
      bool mine = ids.empty();
      for (const Waypoint& w : waypoints_) {
        mine = mine || std::find(ids.begin(), ids.end(), w.wp.order_id()) != ids.end();
      }
      if (!mine || waypoints_.empty()) break;
      // Stop at the next waypoint, as a plain stop; everything after it is void.
      Waypoint next = waypoints_.front();
      next.wp.set_action(v1::WAYPOINT_ACTION_MOVE);
      next.wp.set_dwell(0.0);
      next.wp.clear_order_id();
      waypoints_.assign(1, next);
      break;
    }
    default:
      break;
  }
  if (held_ || message.has_assignment() || message.has_plan_update() || message.has_cancel()) {
    ready_since_.reset();  // a traffic wait, or a new plan: not a release it waited for
  } else if (ready_since_ && released_up_to_ > horizon_before && waypoints_.size() > 1 &&
             MayDriveTo(waypoints_[1])) {
    if (released_after && now >= 0.0) *released_after = std::max(0.0, now - *ready_since_);
    ready_since_.reset();
  }
  return true;
}

bool SimRobot::MayDriveTo(const Waypoint& w) const {
  return w.wp.sequence() <= released_up_to_;
}

void SimRobot::ArriveAt(Waypoint& w, double time, std::vector<v1::RobotMessage>& out) {
  w.arrived = true;
  w.reported = now_;
  position_ = Xy(w.wp);
  if (w.wp.has_heading()) {  // a planned pose (four-wheel steer): reached with its heading
    heading_ = w.wp.heading();
    has_heading_ = true;
  }
  last_reached_ = std::max(last_reached_, w.wp.sequence());
  v1::RobotMessage m;
  m.mutable_waypoint_reached()->set_sequence(w.wp.sequence());
  m.mutable_waypoint_reached()->mutable_pose()->set_x(position_.x());
  m.mutable_waypoint_reached()->mutable_pose()->set_y(position_.y());
  m.mutable_waypoint_reached()->mutable_pose()->set_theta(heading_);
  out.push_back(std::move(m));
  if (w.wp.dwell() > 0.0) {
    dwelling_ = true;
    dwell_until_ = time + w.wp.dwell();
    dwell_wp_ = w.wp;
  } else if (IsTask(w.wp)) {
    Finished(w.wp, out);
  }
}

void SimRobot::Finished(const v1::TimedWaypoint& w, std::vector<v1::RobotMessage>& out) {
  out.push_back(TaskEventFor(w));
  if (w.action() != v1::WAYPOINT_ACTION_DROP) return;
  finished_drops_.emplace_back(w.sequence(), w.order_id());
  if (finished_drops_.size() > kMaxFinishedDrops) finished_drops_.pop_front();
}

void SimRobot::Step(double now, std::vector<v1::RobotMessage>& out) {
  if (muted_) {
    current_speed_ = 0.0;
    repeats_.clear();
    return;
  }
  for (v1::RobotMessage& m : repeats_) out.push_back(std::move(m));
  repeats_.clear();
  if (!started_) {
    started_ = true;
    now_ = now;
  }
  double t = now_;  // the time reached so far within this step
  now_ = std::max(now_, now);
  current_speed_ = 0.0;
  for (int guard = 0; guard < 100000; ++guard) {
    if (dwelling_) {
      if (dwell_until_ > now_) break;
      dwelling_ = false;
      t = std::max(t, dwell_until_);
      if (!waypoints_.empty()) waypoints_.front().reported = std::max(waypoints_.front().reported, dwell_until_);
      if (IsTask(dwell_wp_)) Finished(dwell_wp_, out);
      continue;
    }
    if (waypoints_.empty()) break;
    Waypoint& front = waypoints_.front();
    if (front.arrived) {
      if (waypoints_.size() == 1) break;  // plan done: stand here
      if (held_ && (hold_at_ == 0 || hold_at_ <= front.wp.sequence())) break;
      const double depart = front.wp.eta() + front.wp.dwell();
      if (!MayDriveTo(waypoints_[1])) {
        // Ready to go but not released: since the later of its arrival's report and the
        // planned departure.
        if (!ready_since_ && depart <= now_) ready_since_ = std::max(front.reported, depart);
        break;
      }
      if (depart > now_) break;  // ahead of plan: wait for the planned departure
      t = std::max(t, depart);
      waypoints_.pop_front();
      continue;
    }
    // Driving to `front`.
    if (stalled_ || (held_ && hold_at_ == 0) || !MayDriveTo(front)) break;
    const Eigen::Vector2d to = Xy(front.wp);
    const Eigen::Vector2d d = to - position_;
    const double dist = d.norm();
    const double v = speed_ * slow_factor_;
    if (dist <= kArriveEps) {
      ArriveAt(front, t, out);
      continue;
    }
    if (v <= 0.0 || t >= now_) break;
    const double want = std::atan2(d.y(), d.x());
    // Four-wheel steer in a free space: its modes, no turn first. (A waypoint with a heading
    // and no mode, where the robot enters a free space, is reached along its lane.)
    const bool posed = front.wp.has_heading() && front.wp.motion_mode() != v1::MOTION_MODE_UNSPECIFIED;
    if (turning_to_ != front.wp.sequence()) {  // a new leg: turn to it first
      turning_to_ = front.wp.sequence();
      leg_from_ = position_;
      leg_from_heading_ = heading_;
      const double angle =
          has_heading_ && !posed ? std::abs(std::remainder(want - heading_, 2.0 * std::numbers::pi)) : 0.0;
      turn_end_ = t + turn_time_ * angle / (std::numbers::pi / 2.0);
    }
    if (turn_end_ > t) {
      if (turn_end_ >= now_) break;  // still turning, standing
      t = turn_end_;
    }
    if (!posed) heading_ = want;
    has_heading_ = true;
    current_speed_ = v;
    const double reach = v * (now_ - t);
    if (reach + kArriveEps >= dist) {
      t += dist / v;
      ArriveAt(front, t, out);
      continue;
    }
    position_ += d * (reach / dist);
    if (posed) {  // the heading turns evenly over the leg (unchanged on a straight or a crab)
      const double leg = (to - leg_from_).norm();
      const double done = leg > 0.0 ? (position_ - leg_from_).norm() / leg : 1.0;
      heading_ = std::remainder(
          leg_from_heading_ + done * std::remainder(front.wp.heading() - leg_from_heading_, 2.0 * std::numbers::pi),
          2.0 * std::numbers::pi);
    }
    break;
  }
}

bool SimRobot::idle() const {
  return !dwelling_ &&
         (waypoints_.empty() || (waypoints_.size() == 1 && waypoints_.front().arrived));
}

v1::RobotMessage SimRobot::Report() const {
  v1::RobotMessage m;
  v1::StateReport* r = m.mutable_state_report();
  r->mutable_pose()->set_x(position_.x());
  r->mutable_pose()->set_y(position_.y());
  r->mutable_pose()->set_theta(heading_);
  r->set_speed(current_speed_);
  v1::RobotState state = v1::ROBOT_STATE_IDLE;
  if (stalled_) {
    state = v1::ROBOT_STATE_FAULT;
  } else if (dwelling_) {
    state = v1::ROBOT_STATE_WORKING;
  } else if (current_speed_ > 0.0) {
    state = v1::ROBOT_STATE_MOVING;
  } else if (!idle()) {
    state = v1::ROBOT_STATE_WAITING;
  }
  r->set_state(state);
  r->set_last_waypoint_sequence(last_reached_);
  return m;
}

}  // namespace dispatch::clients
