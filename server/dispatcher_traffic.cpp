// Dispatcher: traffic control on the wire. The core's TrafficGate (engine/traffic/traffic_gate.h)
// runs the engine's TrafficController on what robots report; here its Grants, Holds, Resumes
// and PlanUpdates go out, re-planned legs are stored, and blocked robots give their orders back.
#include <spdlog/spdlog.h>

#include "server/dispatcher.h"

namespace dispatch::server {

OrderRoutes Dispatcher::RoutesOf(const std::string& order_id) const { return core_->RoutesOf(order_id); }

std::vector<std::pair<std::string, std::string>> Dispatcher::TrafficLines() const {
  std::vector<std::pair<std::string, std::string>> out;
  const std::string awaiting = restart_wait_.List();
  const engine::TrafficGate* gate = core_->gate();
  for (const auto& [id, r] : core_->robots()) {
    std::string line = gate ? gate->Describe(id) : std::string("traffic control off");
    if (!awaiting.empty()) line += "; nothing released until these robots report after the restart: " + awaiting;
    out.emplace_back(id, std::move(line));
  }
  return out;
}

void Dispatcher::EndRecoveryWait(bool timed_out) {
  if (timed_out) {
    for (const auto& id : restart_wait_.awaited()) {
      if (const RobotSession* s = sessions_.Find(id); s && !s->link) core_->Place(id);
    }
    spdlog::warn("traffic control resumes after {:.1f} s without a report from {} (placed at their stored points)",
                 options_.heartbeat_timeout, restart_wait_.List());
  } else {
    spdlog::info("every robot that was on line before the restart has reported: traffic control resumes");
  }
  restart_wait_.End();
  effects_.MarkChanged();
}

void Dispatcher::StepTraffic() {
  const engine::TrafficGate* gate = core_->gate();
  if (!gate) return;
  if (restart_wait_.waiting()) {  // after a restart: nothing moves until the fleet is known
    if (!restart_wait_.Expired(Clock::now())) return;
    EndRecoveryWait(true);
  }
  const double now = Now();
  engine::StepOutcome step = core_->Step(now);
  if (!step.messages.empty()) effects_.MarkChanged();  // the snapshot shows grants and holds
  for (auto& c : step.messages) {
    RobotSession* session = sessions_.Find(c.robot);
    if (!session) continue;
    if (c.message.kind == RobotOutbound::Kind::kHold) spdlog::debug("hold {}: {}", c.robot, c.message.reason);
    const std::optional<double> waited = TrackHold(*session, c.message.kind, now);
    if (waited && options_.metrics) options_.metrics->ObserveGrantWait(*waited);
    SendTo(c.robot, std::move(c.message));
  }
  for (const engine::Assignment& a : step.rewritten) {
    if (auto saved = store_.SaveAssignment(a); !saved.ok()) {
      // The robot drives the new leg all the same (the controller has it); a restart falls
      // back to the stored plan and re-routes from where the robot stands.
      spdlog::warn("re-planned leg of {} not stored: {}", a.robot_id, saved.error().message);
    }
  }
  for (const auto& [id, why] : step.blocked) {
    spdlog::warn("robot {} blocked: {} ({})", id, why, gate->Describe(id));
    for (const auto& [other, r] : core_->robots()) spdlog::debug("traffic: {}", gate->Describe(other));
    effects_.MarkChanged();
    LoseRobot(id, "robot " + id + " blocked: " + why);
  }
  if (!step.recovered.empty()) effects_.MarkChanged();  // fault -> idle shows on the map
  for (const std::string& note : step.notes) spdlog::info("{}", note);
  if (distances_.SampleDue(Clock::now())) core_->SampleDistances(now);
  const engine::MinDistance& d = gate->min_distance();
  if (distances_.Update(d)) {
    if (d.distance < options_.traffic.point_clearance - 1e-6) {
      spdlog::warn("robots {} and {} {:.3f} m apart (closer than eps1): {} | {}", d.a, d.b, d.distance,
                   gate->Describe(d.a), gate->Describe(d.b));
    }
    effects_.MarkChanged();
  }
}

}  // namespace dispatch::server
