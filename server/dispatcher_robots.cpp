// Dispatcher: robot streams (hello, reports, progress events), heartbeats and the offline
// grace that re-allocates a lost robot's orders (their rules: robot_protocol.h). What a report
// means is the core's (engine/dispatch/dispatch_core.h); here it is received, stored and
// answered.
#include <spdlog/spdlog.h>

#include <optional>

#include "engine/common/text.h"
#include "engine/dispatch/robot_intake.h"
#include "server/dispatcher.h"
#include "server/robot_protocol.h"

namespace dispatch::server {

void Dispatcher::OnRobotStreamOpened(std::shared_ptr<RobotLink> link) {
  Post([this, link = std::move(link)] { awaiting_hello_.emplace(link, Clock::now()); });
}

void Dispatcher::OnRobotMessage(std::shared_ptr<RobotLink> link, RobotInbound message) {
  Post([this, link = std::move(link), message = std::move(message)] { DoRobotMessage(link, message); });
}

void Dispatcher::CommandRobot(engine::RobotCommandKind kind, std::string robot_id, std::string station,
                              std::string actor, std::function<void(ServiceStatus)> done) {
  Post([this, kind, id = std::move(robot_id), station = std::move(station), actor = std::move(actor),
        done = std::move(done)] {
    ServiceStatus reply = DoCommand({kind, id, actor, engine::kNoPoint}, station);
    if (reply.ok()) {
      spdlog::info("robot {}: {}{} by {}", id, engine::RobotCommandName(kind), station.empty() ? "" : " to " + station,
                   actor.empty() ? "an operator" : actor);
    }
    effects_.MarkChanged();
    Defer([done, reply = std::move(reply)] { done(reply); });
  });
}

ServiceStatus Dispatcher::DoCommand(engine::OperatorCommand command, const std::string& station) {
  auto refused = [](const engine::Error& e) {  // an unknown robot or station: NOT_FOUND
    return e.code == engine::ErrorCode::kNotFound ? MakeStatus(StatusCode::kNotFound, e.message) : FromEngineError(e);
  };
  if (command.kind == engine::RobotCommandKind::kSend) {
    auto point = engine::StationPoint(*map_, station);
    if (!point.ok()) return refused(point.error());
    command.to = *point;
  }
  auto change = core_->PlanCommand(command, Now());
  if (!change.ok()) return refused(change.error());
  ServiceStatus status;
  if (!Commit(*change, nullptr, &status, command.by)) return status;
  return {};
}

void Dispatcher::OnRobotGone(std::shared_ptr<RobotLink> link) {
  Post([this, link = std::move(link)] { DoRobotGone(link); });
}

void Dispatcher::DoRobotMessage(const std::shared_ptr<RobotLink>& link, const RobotInbound& m) {
  awaiting_hello_.erase(link);  // it spoke: a Hello, or a first message that ends it
  const std::string* known = sessions_.RobotOf(link.get());
  if (auto wrong = OutOfTurn(m.kind, known != nullptr)) {
    return CloseLink(link, MakeStatus(StatusCode::kInvalidArgument, *wrong));
  }
  if (m.kind == RobotInbound::Kind::kHello) return DoHello(link, m);
  const std::string id = *known;
  RobotSession* session = sessions_.Find(id);
  if (!session || session->link != link) return;  // a superseded stream
  RobotSession& s = *session;
  s.last_heard = Clock::now();
  s.last_seen = Now();
  effects_.MarkChanged();
  switch (m.kind) {
    case RobotInbound::Kind::kState: {
      engine::ReportOutcome report = core_->Report(id, m.pose, m.arc_id, m.state, m.battery, m.sequence, Now());
      if (!report.taken) return;  // a pose off the floor: no news
      if (restart_wait_.Reported(id)) EndRecoveryWait(false);
      Progressed(id, std::move(report));
      break;
    }
    case RobotInbound::Kind::kWaypointReached: {
      const std::optional<engine::Pose> pose = m.has_pose ? std::optional<engine::Pose>(m.pose) : std::nullopt;
      engine::ReportOutcome arrival = core_->Reached(id, m.sequence, pose, Now());
      if (!arrival.taken) return Implausible(id, "reached waypoint " + std::to_string(m.sequence), arrival.why);
      Progressed(id, std::move(arrival));
      break;
    }
    case RobotInbound::Kind::kTaskEvent: DoTaskEvent(id, {m.order_id, m.dropped}); break;
    case RobotInbound::Kind::kAck: TakeAck(s, m.sequence); break;
    case RobotInbound::Kind::kHeartbeat:
    case RobotInbound::Kind::kHello: break;
  }
}

void Dispatcher::DoHello(const std::shared_ptr<RobotLink>& link, const RobotInbound& hello) {
  auto reject = [&](StatusCode code, std::string message) {
    spdlog::warn("robot hello rejected: {}", engine::Clipped(message, 512));
    CloseLink(link, MakeStatus(code, std::move(message)));
  };
  auto located = engine::LocateRobot(*map_, hello.robot_id, hello.pose, options_.robot_snap_tolerance);
  if (!located.ok()) return reject(StatusCode::kInvalidArgument, located.error().message);
  const engine::PointId point = *located;
  const std::string& id = hello.robot_id;
  const RobotSession* existing = sessions_.Find(id);
  if (existing && existing->link && existing->link != link) {
    if (auto live = LiveStream(id, *existing, Clock::now(), options_.heartbeat_timeout)) {
      return reject(StatusCode::kAlreadyExists, *live);
    }
    CloseLink(sessions_.Detach(id), MakeStatus(StatusCode::kUnavailable, "superseded by a new stream"));
  }
  const storage::RobotRecord record = HelloRecord(RecordOf(id), hello, point, options_.allocation.speed, Now());
  if (auto valid = engine::ValidateRobot(record.robot); !valid.ok()) {
    return reject(StatusCode::kInvalidArgument, valid.error().message);
  }
  const bool resend = HasOrders(core_->robot(id));
  storage::RobotRecord stored = record;
  stored.next_sequence += resend ? 2 : 1;  // Welcome (+ the current plan)
  if (auto saved = store_.UpsertRobot(stored); !saved.ok()) {
    return reject(StatusCode::kUnavailable, "robot " + id + " not registered: storage failed: " + saved.error().message);
  }
  RobotSession& s = sessions_.Get(id);
  RestoreSession(s, record);
  sessions_.Attach(id, link);
  s.last_heard = Clock::now();
  s.offline_since.reset();
  effects_.MarkChanged();
  std::vector<engine::RobotCommand> plan = core_->Connect(record.robot, Now());
  RobotOutbound welcome;
  welcome.kind = RobotOutbound::Kind::kWelcome;
  welcome.time_scale = options_.time_scale;
  welcome.heartbeat_interval = options_.heartbeat_interval;
  welcome.heartbeat_timeout = options_.heartbeat_timeout;
  welcome.resume_from_sequence = record.last_acked_sequence + 1;
  welcome.map_version = options_.map_version;
  SendTo(id, std::move(welcome));
  Send(std::move(plan));
  spdlog::info("robot {} connected at '{}'", id, map_->point(point).name);
}

void Dispatcher::Progressed(const std::string& id, engine::ReportOutcome outcome) {
  if (outcome.change && !Commit(*outcome.change, nullptr)) {
    spdlog::error("order start reported by {} not stored", id);
  }
  for (const engine::TaskReport& report : outcome.retry) DoTaskEvent(id, report);
}

void Dispatcher::Implausible(const std::string& id, const std::string& what, const std::string& why) {
  ++implausible_;
  effects_.MarkChanged();
  spdlog::warn("robot {}: '{}' not taken: {}", id, what, why);
}

void Dispatcher::DoTaskEvent(const std::string& id, const engine::TaskReport& report) {
  engine::TaskOutcome outcome = core_->PlanTask(id, report, Now());
  switch (outcome.kind) {
    case engine::TaskOutcome::Kind::kIgnored: return;
    case engine::TaskOutcome::Kind::kWaiting:
      if (outcome.overflowed) Implausible(id, "an older pick or drop", "too many wait for the robot's progress");
      spdlog::debug("robot {}: '{}' waits for its progress: {}", id, outcome.what, outcome.why);
      return;
    case engine::TaskOutcome::Kind::kImplausible: return Implausible(id, outcome.what, outcome.why);
    case engine::TaskOutcome::Kind::kChange:
      if (!Commit(outcome.change, nullptr)) spdlog::error("robot {}: '{}' not stored", id, outcome.what);
      return;
  }
}

void Dispatcher::MarkOffline(const std::string& id, const std::string& why) {
  RobotSession& s = sessions_.Get(id);
  if (auto link = sessions_.Detach(id)) CloseLink(link, MakeStatus(StatusCode::kUnavailable, why));
  s.offline_since = Clock::now();
  effects_.MarkChanged();
  core_->Disconnect(id);
  if (auto saved = store_.UpsertRobot(RecordOf(id)); !saved.ok()) {
    spdlog::warn("robot {} offline state not stored: {}", id, saved.error().message);
  }
  spdlog::warn("robot {} offline: {}", id, why);
}

void Dispatcher::DoRobotGone(const std::shared_ptr<RobotLink>& link) {
  awaiting_hello_.erase(link);
  const std::string* known = sessions_.RobotOf(link.get());
  if (!known) return;
  const std::string id = *known;
  if (const RobotSession* s = sessions_.Find(id); s && s->link == link) MarkOffline(id, "stream closed");
  sessions_.Forget(link.get());
}

bool Dispatcher::LoseRobot(const std::string& id, const std::string& why) {
  const engine::Change change = core_->PlanLoss(id, why, Now());
  if (!Commit(change, nullptr)) {
    rounds_due_.Retry();  // tried again on the next tick
    return false;
  }
  return true;
}

void Dispatcher::Tick() {
  const auto now = Clock::now();
  for (auto& [id, s] : sessions_) {
    if (s.link) {
      if (auto why = SilenceTimeout(s, now, options_.heartbeat_timeout)) MarkOffline(id, *why);
    } else if (auto why = GraceOver(id, s, core_->robot(id), now, options_.offline_grace)) {
      if (LoseRobot(id, *why)) s.offline_since.reset();
    }
  }
  const auto hello_deadline = WallDuration(options_.heartbeat_timeout);
  for (auto it = awaiting_hello_.begin(); it != awaiting_hello_.end();) {
    if (now - it->second < hello_deadline) {
      ++it;
      continue;
    }
    CloseLink(it->first, MakeStatus(StatusCode::kDeadlineExceeded,
                                    "no Hello within the heartbeat timeout (" +
                                        engine::FormatFixed(options_.heartbeat_timeout) + " s)"));
    it = awaiting_hello_.erase(it);
  }
  rounds_due_.Tick();
  memory_trim_.Tick(now);
}

}  // namespace dispatch::server
