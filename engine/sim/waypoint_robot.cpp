#include "engine/sim/waypoint_robot.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace dispatch::engine {
namespace {

constexpr double kArriveEps = 1e-9;

bool IsTask(const Waypoint& w) { return w.action == WaypointAction::kPick || w.action == WaypointAction::kDrop; }

}  // namespace

WaypointRobot::WaypointRobot(std::string id, const Eigen::Vector2d& xy, double speed, double turn_time)
    : xy_(xy), speed_(speed), turn_time_(turn_time), id_(std::move(id)) {}

bool WaypointRobot::idle() const {
  return !dwelling_ && (stops_.empty() || (stops_.size() == 1 && stops_.front().arrived));
}

void WaypointRobot::Adopt(const std::vector<MessageWaypoint>& wps) {
  for (const MessageWaypoint& w : wps) {
    const auto seq = static_cast<std::uint64_t>(w.waypoint.seq);
    if (seq <= last_reached_) continue;  // reached already (a plan sent again)
    if (!stops_.empty() && w.waypoint.seq <= stops_.back().wp.seq) continue;
    stops_.push_back({w.waypoint, w.order_id, false});
    if (w.released) released_up_to_ = std::max(released_up_to_, seq);
  }
}

void WaypointRobot::Apply(const RobotMessage& m) {
  using Kind = RobotMessage::Kind;
  switch (m.kind) {
    case Kind::kAssignment:
      stops_.clear();
      Adopt(m.waypoints);
      released_up_to_ = std::max(released_up_to_, m.released_up_to);
      break;
    case Kind::kPlanUpdate:
      while (!stops_.empty() && static_cast<std::uint64_t>(stops_.back().wp.seq) >= m.from_sequence) stops_.pop_back();
      Adopt(m.waypoints);
      released_up_to_ = std::max(released_up_to_, m.released_up_to);
      break;
    case Kind::kGrant: released_up_to_ = std::max(released_up_to_, m.released_up_to); break;
    case Kind::kHold:
      held_ = true;
      hold_at_ = m.stop_at_sequence;
      break;
    case Kind::kResume:
      held_ = false;
      hold_at_ = 0;
      released_up_to_ = std::max(released_up_to_, m.released_up_to);
      break;
    case Kind::kCancel: {
      bool mine = m.order_ids.empty();
      for (const Stop& s : stops_) {
        mine = mine || std::find(m.order_ids.begin(), m.order_ids.end(), s.order_id) != m.order_ids.end();
      }
      if (!mine || stops_.empty()) break;
      // Stop at the next waypoint, as a plain stop; everything after it is void.
      Stop next = stops_.front();
      next.wp.action = WaypointAction::kMove;
      next.wp.dwell = 0.0;
      next.order_id.clear();
      stops_.clear();
      stops_.push_back(std::move(next));
      break;
    }
    case Kind::kWelcome: break;
  }
}

void WaypointRobot::Finish(const Stop& s, std::vector<RobotEvent>& out) const {
  if (!IsTask(s.wp) || s.order_id.empty()) return;
  const auto kind = s.wp.action == WaypointAction::kPick ? RobotEvent::Kind::kPicked : RobotEvent::Kind::kDropped;
  out.push_back({kind, static_cast<std::uint64_t>(s.wp.seq), s.order_id});
}

void WaypointRobot::Arrive(Stop& s, double t, std::vector<RobotEvent>& out) {
  s.arrived = true;
  xy_ = s.wp.xy;
  last_reached_ = std::max(last_reached_, static_cast<std::uint64_t>(s.wp.seq));
  out.push_back({RobotEvent::Kind::kReached, static_cast<std::uint64_t>(s.wp.seq), {}});
  if (s.wp.dwell > 0.0) {
    dwelling_ = true;
    dwell_until_ = t + s.wp.dwell;
    dwell_stop_ = s;
  } else {
    Finish(s, out);
  }
}

void WaypointRobot::Step(double now, std::vector<RobotEvent>& out) {
  if (!started_) {
    started_ = true;
    now_ = now;
  }
  double t = now_;  // the time reached so far within this step
  now_ = std::max(now_, now);
  moving_ = false;
  for (int guard = 0; guard < 100000; ++guard) {
    if (dwelling_) {
      if (dwell_until_ > now_) break;
      dwelling_ = false;
      t = std::max(t, dwell_until_);
      Finish(dwell_stop_, out);
      continue;
    }
    if (stops_.empty()) break;
    Stop& front = stops_.front();
    if (front.arrived) {
      if (stops_.size() == 1) break;  // plan done: stand here
      if (held_ && (hold_at_ == 0 || hold_at_ <= static_cast<std::uint64_t>(front.wp.seq))) break;
      const double depart = front.wp.departure();
      if (!Released(stops_[1]) || depart > now_) break;  // not released, or ahead of plan
      t = std::max(t, depart);
      stops_.pop_front();
      continue;
    }
    if ((held_ && hold_at_ == 0) || !Released(front)) break;
    const Eigen::Vector2d d = front.wp.xy - xy_;
    const double dist = d.norm();
    if (dist <= kArriveEps) {
      Arrive(front, t, out);
      continue;
    }
    if (speed_ <= 0.0 || t >= now_) break;
    const double want = std::atan2(d.y(), d.x());
    if (turning_to_ != front.wp.seq) {  // a new leg: turn to it first (Wang2019's t_c)
      turning_to_ = front.wp.seq;
      const double angle = has_heading_ ? std::abs(std::remainder(want - heading_, 2.0 * std::numbers::pi)) : 0.0;
      turn_end_ = t + turn_time_ * angle / (std::numbers::pi / 2.0);
    }
    if (turn_end_ > t) {
      if (turn_end_ >= now_) break;  // still turning, standing
      t = turn_end_;
    }
    heading_ = want;
    has_heading_ = true;
    moving_ = true;
    const double reach = speed_ * (now_ - t);
    if (reach + kArriveEps >= dist) {
      t += dist / speed_;
      driven_ += dist;
      Arrive(front, t, out);
      continue;
    }
    xy_ += d * (reach / dist);
    driven_ += reach;
    break;
  }
}

}  // namespace dispatch::engine
