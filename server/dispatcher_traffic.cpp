// Dispatcher: traffic control on the wire. The TrafficGate (engine/traffic/traffic_gate.h) runs the
// engine's TrafficController on what robots report; here its effects become Grant, Hold,
// Resume and PlanUpdate messages, and blocked robots give their orders back.
#include <spdlog/spdlog.h>

#include <algorithm>

#include "engine/dispatch/order_release.h"
#include "server/dispatcher.h"

namespace dispatch::server {

engine::GatePlan Dispatcher::GatePlanOf(const RobotRuntime& r) const {
  std::map<std::string, std::vector<std::string>> teams;
  for (const auto& id : r.assignment.order_ids) {
    auto view = Find(id);
    if (view && view->record.order.formation) teams[id] = view->record.robots;
  }
  return engine::ToGatePlan(r.assignment, std::move(teams));
}

void Dispatcher::SyncGate(const RobotRuntime& r) {
  if (!gate_) return;
  spdlog::debug("plan of {}: {} waypoints, orders {}", r.record.robot.id, r.assignment.plan.waypoints.size(),
                r.assignment.order_ids.size());
  if (r.has_assignment) {
    gate_->SetPlan(r.record.robot.id, GatePlanOf(r));
  } else {
    gate_->SetPlan(r.record.robot.id, engine::GatePlan{});
  }
}

std::uint64_t Dispatcher::ReleasedUpTo(const RobotRuntime& r) const {
  const auto& w = r.assignment.plan.waypoints;
  if (!gate_) return w.empty() ? 0 : static_cast<std::uint64_t>(w.back().seq);
  return gate_->ReleasedUpTo(r.record.robot.id);
}

std::vector<std::pair<std::string, std::string>> Dispatcher::TrafficLines() const {
  std::vector<std::pair<std::string, std::string>> out;
  const std::string awaiting = AwaitedList();
  for (const auto& [id, r] : robots_) {
    std::string line = gate_ ? gate_->Describe(id) : std::string("traffic control off");
    if (!awaiting.empty()) line += "; nothing released until these robots report after the restart: " + awaiting;
    out.emplace_back(id, std::move(line));
  }
  return out;
}

void Dispatcher::PlaceAway(const RobotRuntime& r) {
  const engine::PointId p = r.record.robot.current_point;
  if (!gate_ || p == engine::kNoPoint || static_cast<std::size_t>(p) >= map_->points().size()) return;
  gate_->Connect(r.record.robot.id, map_->point(p).position, p);
  gate_->Disconnect(r.record.robot.id);
}

std::string Dispatcher::AwaitedList() const {
  std::string out;
  for (const auto& id : awaiting_reconnect_) out += (out.empty() ? "" : ", ") + id;
  return out;
}

void Dispatcher::Reported(const std::string& robot_id) {
  if (awaiting_reconnect_.erase(robot_id) == 0) return;
  dirty_ = true;
  if (awaiting_reconnect_.empty()) EndRecoveryWait(false);
}

void Dispatcher::EndRecoveryWait(bool timed_out) {
  if (timed_out) {
    for (const auto& id : awaiting_reconnect_) {
      if (auto it = robots_.find(id); it != robots_.end() && !it->second.link) PlaceAway(it->second);
    }
    spdlog::warn("traffic control resumes after {:.1f} s without a report from {} (placed at their stored points)",
                 options_.heartbeat_timeout, AwaitedList());
  } else {
    spdlog::info("every robot that was on line before the restart has reported: traffic control resumes");
  }
  awaiting_reconnect_.clear();
  dirty_ = true;
}

void Dispatcher::StepTraffic() {
  if (!gate_) return;
  if (!awaiting_reconnect_.empty()) {  // after a restart: nothing moves until the fleet is known
    if (Clock::now() < awaiting_until_) return;
    EndRecoveryWait(true);
  }
  const double now = Now();
  std::vector<engine::GateEffect> effects = gate_->Step(now);
  for (engine::GateEffect& e : effects) ApplyGateEffect(e);
  for (const std::string& note : gate_->TakeNotes()) spdlog::info("{}", note);
  if (const auto wall = Clock::now(); wall >= next_distance_sample_) {  // 20 Hz: reports come at ~10
    gate_->SampleDistances(now);
    next_distance_sample_ = wall + std::chrono::milliseconds(50);
  }
  const engine::MinDistance& d = gate_->min_distance();
  if (d.distance != min_distance_.distance || d.time != min_distance_.time) {
    if (d.distance < options_.traffic.point_clearance - 1e-6) {
      spdlog::warn("robots {} and {} {:.3f} m apart (closer than eps1): {} | {}", d.a, d.b, d.distance,
                   gate_->Describe(d.a), gate_->Describe(d.b));
    }
    min_distance_ = d;
    dirty_ = true;
  }
}

void Dispatcher::ApplyGateEffect(engine::GateEffect& e) {
  RobotRuntime* r = RobotOf(e.robot);
  if (!r) return;
  dirty_ = true;  // the snapshot shows grants and holds (intersections, robots' hold state)
  switch (e.kind) {
    case engine::GateEffect::Kind::kRelease: {
      RobotOutbound m;
      m.released_up_to = e.release_up_to;
      if (r->held_since) {
        if (options_.metrics) options_.metrics->ObserveGrantWait(Now() - *r->held_since);
        r->held_since.reset();
      }
      if (e.resume) {
        m.kind = RobotOutbound::Kind::kResume;
      } else {
        m.kind = RobotOutbound::Kind::kGrant;
        m.intersection_id = e.intersection;
        if (e.intersection >= 0 && static_cast<std::size_t>(e.intersection) < map_->intersections().size()) {
          m.intersection_name = map_->intersections()[static_cast<std::size_t>(e.intersection)].name;
        } else {
          m.intersection_id = -1;
        }
        ++traffic_counts_.grants;
      }
      SendTo(*r, std::move(m));
      break;
    }
    case engine::GateEffect::Kind::kHold: {
      RobotOutbound m;
      m.kind = RobotOutbound::Kind::kHold;
      m.stop_at_sequence = e.hold_at;
      m.reason = e.reason;
      ++traffic_counts_.holds;
      if (!r->held_since) r->held_since = Now();
      spdlog::debug("hold {}: {}", e.robot, e.reason);
      SendTo(*r, std::move(m));
      break;
    }
    case engine::GateEffect::Kind::kRewrite: {
      storage::AssignmentRecord a = r->assignment;
      if (a.robot_id.empty()) {  // an idle robot without a stored plan sent aside
        a.robot_id = a.plan.robot_id = e.robot;
      }
      a.plan.waypoints = std::move(e.waypoints);
      if (!a.plan.waypoints.empty()) {
        a.released_up_to = std::max<std::int64_t>(a.released_up_to, a.plan.waypoints.back().seq);
      }
      a.updated_time = Now();
      if (auto saved = store_.SaveAssignment(a); !saved.ok()) {
        // The robot drives the new leg all the same (the controller has it); a restart falls
        // back to the stored plan and re-routes from where the robot stands.
        spdlog::warn("re-planned leg of {} not stored: {}", e.robot, saved.error().message);
      }
      r->assignment = std::move(a);
      r->has_assignment = true;
      ++traffic_counts_.replans;
      spdlog::debug("re-plan {} from waypoint {}: {} waypoints", e.robot, e.from_sequence,
                    r->assignment.plan.waypoints.size());
      SendTo(*r, PlanMessage(*r, false, e.from_sequence));
      dirty_ = true;
      break;
    }
    case engine::GateEffect::Kind::kBlocked: {
      spdlog::warn("robot {} blocked: {} ({})", e.robot, e.reason, gate_->Describe(e.robot));
      for (const auto& [id, other] : robots_) spdlog::debug("traffic: {}", gate_->Describe(id));
      r->record.robot.state = engine::RobotState::kFault;
      dirty_ = true;
      if (!r->has_assignment || r->assignment.order_ids.empty()) break;
      ServiceStatus status;
      auto target = [](const OrderView& v) { return engine::StateAfterRobotLoss(v.record.order.state); };
      if (ReleaseOrders(r->assignment.order_ids, target, "robot " + e.robot + " blocked: " + e.reason, &status)) {
        retry_allocation_ = true;
      }
      break;
    }
  }
}

}  // namespace dispatch::server
