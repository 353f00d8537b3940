// Dispatcher: robot streams (hello, reports, progress events), heartbeats and the offline
// grace that re-allocates a lost robot's orders.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "engine/dispatch/order_release.h"
#include "engine/dispatch/report_check.h"
#include "engine/dispatch/robot_intake.h"
#include "server/dispatcher.h"

namespace dispatch::server {

void Dispatcher::OnRobotMessage(std::shared_ptr<RobotLink> link, RobotInbound message) {
  Post([this, link = std::move(link), message = std::move(message)] { DoRobotMessage(link, message); });
}

void Dispatcher::OnRobotGone(std::shared_ptr<RobotLink> link) {
  Post([this, link = std::move(link)] { DoRobotGone(link); });
}

void Dispatcher::DoRobotMessage(const std::shared_ptr<RobotLink>& link, const RobotInbound& m) {
  auto known = link_robot_.find(link.get());
  if (m.kind == RobotInbound::Kind::kHello) {
    if (known != link_robot_.end()) {
      CloseLink(link, MakeStatus(StatusCode::kInvalidArgument, "Hello sent twice on one stream"));
      return;
    }
    DoHello(link, m);
    return;
  }
  if (known == link_robot_.end()) {
    CloseLink(link, MakeStatus(StatusCode::kInvalidArgument, "the first message of a stream must be Hello"));
    return;
  }
  RobotRuntime* r = RobotOf(known->second);
  if (!r || r->link != link) return;  // a superseded stream
  r->last_heard = Clock::now();
  r->record.last_seen = Now();
  dirty_ = true;
  switch (m.kind) {
    case RobotInbound::Kind::kState: {
      // A pose off the floor (NaN, 1e300, a wrong frame) is not news about the robot: it
      // would leave it at no map point and out of every auction. Ignored, like a bad
      // battery value, which would otherwise fail the robot's next Hello (ValidateRobot).
      if (!engine::OnFloor(*map_, m.pose.position, options_.robot_snap_tolerance) || !std::isfinite(m.pose.heading)) {
        return;
      }
      r->record.robot.pose = m.pose;
      if (m.arc_id && *m.arc_id >= 0 && static_cast<std::size_t>(*m.arc_id) < map_->arcs().size()) {
        r->record.robot.current_point = map_->arc(*m.arc_id).to;
      } else {
        r->record.robot.current_point = map_->NearestPoint(m.pose.position);
      }
      if (m.state && *m.state != engine::RobotState::kOffline &&
          r->record.robot.state != engine::RobotState::kFault) {
        r->record.robot.state = *m.state;
      }
      if (m.battery && *m.battery >= 0.0 && *m.battery <= 1.0) r->record.robot.battery = *m.battery;
      // A waypoint beyond the highest ever numbered for this robot was never sent, so it
      // cannot have been passed: such a claim is ignored (the gate would otherwise take the
      // robot to be at its plan's end and disregard its real progress from then on).
      std::uint64_t passed = 0;
      std::vector<engine::TaskReport> retry = engine::TakeStateProgress(r->progress, r->assignment, m.sequence, &passed);
      if (gate_) gate_->Report(r->record.robot.id, m.pose.position, passed, Now());
      if (!awaiting_reconnect_.empty()) Reported(r->record.robot.id);
      RetryTaskEvents(*r, std::move(retry));
      break;
    }
    case RobotInbound::Kind::kWaypointReached: DoWaypointReached(*r, m); break;
    case RobotInbound::Kind::kTaskEvent: DoTaskEvent(*r, {m.order_id, m.dropped}); break;
    case RobotInbound::Kind::kAck:
      // An ack of a sequence never sent is ignored: believed, it would skip what is sent
      // next and (beyond 2^63) make the robot's record unstorable.
      if (m.sequence < r->record.next_sequence) {
        r->record.last_acked_sequence = std::max(r->record.last_acked_sequence, m.sequence);
      }
      break;
    case RobotInbound::Kind::kHeartbeat:
    case RobotInbound::Kind::kHello: break;
  }
}

void Dispatcher::DoHello(const std::shared_ptr<RobotLink>& link, const RobotInbound& hello) {
  auto reject = [&](StatusCode code, std::string message) {
    spdlog::warn("robot hello rejected: {}", message);
    CloseLink(link, MakeStatus(code, std::move(message)));
  };
  auto located = engine::LocateRobot(*map_, hello.robot_id, hello.pose, options_.robot_snap_tolerance);
  if (!located.ok()) return reject(StatusCode::kInvalidArgument, located.error().message);
  const Eigen::Vector2d xy = hello.pose.position;
  const engine::PointId point = *located;
  auto [it, inserted] = robots_.try_emplace(hello.robot_id);
  RobotRuntime& r = it->second;
  if (r.link && r.link != link) {
    const std::chrono::duration<double> silent = Clock::now() - r.last_heard;
    if (silent.count() <= options_.heartbeat_timeout) {
      return reject(StatusCode::kAlreadyExists,
                    "robot " + hello.robot_id + " already has a live stream (heard " +
                        engine::FormatFixed(silent.count()) + " s ago); retry after its heartbeat times out");
    }
    CloseLink(r.link, MakeStatus(StatusCode::kUnavailable, "superseded by a new stream"));
    link_robot_.erase(r.link.get());
    r.link.reset();
  }
  storage::RobotRecord record = r.record;
  record.robot.id = hello.robot_id;
  if (hello.diameter > 0) record.robot.diameter = hello.diameter;
  record.robot.max_speed = hello.max_speed > 0 ? hello.max_speed : options_.allocation.speed;
  record.robot.pose = hello.pose;
  record.robot.pose.position = xy;
  record.robot.current_point = point;
  record.robot.state = engine::RobotState::kIdle;
  if (record.robot.battery && !(*record.robot.battery >= 0.0 && *record.robot.battery <= 1.0)) {
    record.robot.battery.reset();  // stored by an older server that took any report
  }
  record.kind = hello.robot_kind.empty() ? "differential" : hello.robot_kind;
  record.last_seen = Now();
  record.last_acked_sequence = std::max(record.last_acked_sequence, hello.last_acked_sequence);
  if (record.next_sequence <= record.last_acked_sequence) record.next_sequence = record.last_acked_sequence + 1;
  if (auto valid = engine::ValidateRobot(record.robot); !valid.ok()) {
    if (inserted) robots_.erase(it);
    return reject(StatusCode::kInvalidArgument, valid.error().message);
  }
  const bool resend = r.has_assignment && !r.assignment.order_ids.empty();
  storage::RobotRecord stored = record;
  stored.next_sequence += resend ? 2 : 1;  // Welcome (+ the current plan)
  if (auto saved = store_.UpsertRobot(stored); !saved.ok()) {
    if (inserted) robots_.erase(it);
    return reject(StatusCode::kUnavailable, "robot " + hello.robot_id + " not registered: storage failed: " +
                                                saved.error().message);
  }
  r.record = record;
  r.link = link;
  r.last_heard = Clock::now();
  r.offline_since.reset();
  link_robot_[link.get()] = hello.robot_id;
  dirty_ = true;
  RobotOutbound welcome;
  welcome.kind = RobotOutbound::Kind::kWelcome;
  welcome.time_scale = options_.time_scale;
  welcome.heartbeat_interval = options_.heartbeat_interval;
  welcome.heartbeat_timeout = options_.heartbeat_timeout;
  welcome.resume_from_sequence = record.last_acked_sequence + 1;
  welcome.map_version = options_.map_version;
  if (gate_) {
    gate_->Connect(hello.robot_id, xy, point);
    SyncGate(r);
  }
  SendTo(r, std::move(welcome));
  // Resume: the robot gets its whole current plan again (it skips waypoints it has passed).
  if (resend) SendTo(r, PlanMessage(r, true, 0));
  spdlog::info("robot {} connected at '{}'", hello.robot_id, map_->point(point).name);
  allocation_due_ = true;
}

void Dispatcher::StartOrder(const std::string& order_id, const std::string& detail) {
  auto view = Find(order_id);
  if (!view || view->record.order.state != engine::OrderState::kAssigned) return;
  storage::OrderTransition t;
  t.order_id = order_id;
  t.to = engine::OrderState::kInProgress;
  t.time = Now();
  t.detail = detail;
  auto event = store_.TransitionOrder(t);
  if (!event.ok()) {
    spdlog::error("order {} -> in_progress not stored: {}", order_id, event.error().message);
    return;
  }
  auto copy = std::make_shared<OrderView>(*view);
  copy->record.order.state = engine::OrderState::kInProgress;
  copy->record.updated_time = t.time;
  Put(copy);
  Journal(*event);
}

void Dispatcher::DoWaypointReached(RobotRuntime& r, const RobotInbound& m) {
  const auto& w = r.assignment.plan.waypoints;
  const std::optional<Eigen::Vector2d> pose =
      m.has_pose ? std::optional<Eigen::Vector2d>(m.pose.position) : std::nullopt;
  engine::Arrival arrival =
      engine::TakeArrival(r.progress, r.assignment, m.sequence, ReleasedUpTo(r), pose, options_.robot_snap_tolerance);
  if (!arrival.verdict.taken) {
    return Implausible(r, "reached waypoint " + std::to_string(m.sequence), arrival.verdict.why);
  }
  const std::size_t i = arrival.verdict.index;
  r.record.robot.current_point = w[i].point;
  if (!arrival.order.empty()) order_distance_[arrival.order] += arrival.driven;
  if (arrival.xy) {
    r.record.robot.pose.position = *arrival.xy;
    if (pose && std::isfinite(m.pose.heading)) r.record.robot.pose.heading = m.pose.heading;
  }
  if (gate_) gate_->Reached(r.record.robot.id, m.sequence, Now(), arrival.xy);
  if (w[i].action == engine::WaypointAction::kPick) {
    const std::string order = engine::OrderOfWaypoint(r.assignment, i);
    StartOrder(order, r.record.robot.id + " reached pick '" + map_->point(w[i].point).name + "'");
  }
  RetryTaskEvents(r, std::move(arrival.retry));
}

void Dispatcher::RetryTaskEvents(RobotRuntime& r, std::vector<engine::TaskReport> waiting) {
  for (const engine::TaskReport& report : waiting) DoTaskEvent(r, report);
}

void Dispatcher::Implausible(RobotRuntime& r, const std::string& what, const std::string& why) {
  ++traffic_counts_.implausible;
  dirty_ = true;
  spdlog::warn("robot {}: '{}' not taken: {}", r.record.robot.id, what, why);
}

void Dispatcher::DoTaskEvent(RobotRuntime& r, const engine::TaskReport& m) {
  auto view = Find(m.order_id);
  const std::string& robot = r.record.robot.id;
  if (!view || engine::IsTerminal(view->record.order.state)) return;  // late or repeated
  const std::vector<std::string> team = view->record.robots;  // a copy: `view` is replaced below
  if (std::find(team.begin(), team.end(), robot) == team.end()) return;
  if (m.dropped && view->dropped_by.count(robot)) return;  // repeated
  const std::string what = std::string(m.dropped ? "dropped" : "picked") + " for order " + m.order_id;
  const engine::TaskVerdict verdict =
      engine::TakeTaskReport(r.progress, r.assignment, m, r.record.robot.pose.position, options_.robot_snap_tolerance);
  if (verdict.decision == engine::TaskDecision::kWaiting) {
    // E.g. a drop repeated after a restart before the robot's first progress report.
    if (verdict.overflowed) Implausible(r, "an older pick or drop", "too many wait for the robot's progress");
    spdlog::debug("robot {}: '{}' waits for its progress: {}", robot, what, verdict.why);
    return;
  }
  if (verdict.decision == engine::TaskDecision::kRejected) return Implausible(r, what, verdict.why);
  // Where it did it: the stop of its plan (the point id it sent is not needed).
  const std::string where = "'" + map_->point(r.assignment.plan.waypoints[verdict.index].point).name + "'";
  if (!m.dropped) {
    if (view->record.order.state == engine::OrderState::kAssigned) {
      StartOrder(m.order_id, robot + " picked at " + where);
    } else if (auto e = store_.AppendProgress(m.order_id, Now(), robot + " picked at " + where); e.ok()) {
      Journal(*e);
    }
    return;
  }
  StartOrder(m.order_id, robot + " dropped at " + where);
  view = Find(m.order_id);
  engine::DropOutcome drop = engine::PlanDrop(r.assignment, m.order_id, robot, team, view->dropped_by);
  storage::AssignmentRecord& plan = drop.plan;
  const bool trimmed = drop.trimmed;
  const bool complete = drop.complete;
  const double now = Now();
  auto driven = order_distance_.find(m.order_id);
  const double distance = driven != order_distance_.end() ? driven->second : 0.0;
  std::optional<storage::OrderEvent> event;
  auto committed = store_.RunInTransaction([&](storage::Store& s) -> engine::Status {
    if (trimmed) {
      plan.updated_time = now;
      if (auto saved = s.SaveAssignment(plan); !saved.ok()) return saved.error();
    }
    if (complete) {
      storage::OrderTransition t;
      t.order_id = m.order_id;
      t.to = engine::OrderState::kCompleted;
      t.time = now;
      t.detail = robot + " dropped at " + where;
      t.distance = distance;
      auto e = s.TransitionOrder(t);
      if (!e.ok()) return e.error();
      event = *e;
    } else {
      auto e = s.AppendProgress(m.order_id, now, robot + " dropped at " + where);
      if (!e.ok()) return e.error();
      event = *e;
    }
    return engine::Ok{};
  });
  if (!committed.ok()) {
    spdlog::error("drop of order {} by {} not stored: {}", m.order_id, robot, committed.error().message);
    return;
  }
  if (trimmed) {
    r.assignment = std::move(plan);
    r.record.robot.task_queue = r.assignment.order_ids;
    SyncGate(r);
  }
  auto copy = std::make_shared<OrderView>(*view);
  copy->dropped_by = std::move(drop.dropped_by);
  if (complete) {
    copy->record.order.state = engine::OrderState::kCompleted;
    copy->record.updated_time = now;
    copy->finished_time = now;
    copy->record.distance = distance;
    order_distance_.erase(m.order_id);
  }
  Put(copy);
  if (event) Journal(*event);
  if (complete) spdlog::info("order {} completed", m.order_id);
  allocation_due_ = true;
}

void Dispatcher::MarkOffline(RobotRuntime& r, const std::string& why) {
  if (r.link) {
    CloseLink(r.link, MakeStatus(StatusCode::kUnavailable, why));
    link_robot_.erase(r.link.get());
    r.link.reset();
  }
  r.record.robot.state = engine::RobotState::kOffline;
  r.offline_since = Clock::now();
  dirty_ = true;
  if (gate_) gate_->Disconnect(r.record.robot.id);
  if (auto saved = store_.UpsertRobot(r.record); !saved.ok()) {
    spdlog::warn("robot {} offline state not stored: {}", r.record.robot.id, saved.error().message);
  }
  spdlog::warn("robot {} offline: {}", r.record.robot.id, why);
}

void Dispatcher::DoRobotGone(const std::shared_ptr<RobotLink>& link) {
  auto known = link_robot_.find(link.get());
  if (known == link_robot_.end()) return;
  RobotRuntime* r = RobotOf(known->second);
  if (r && r->link == link) MarkOffline(*r, "stream closed");
  link_robot_.erase(link.get());
}

void Dispatcher::Tick() {
  const auto now = Clock::now();
  for (auto& [id, r] : robots_) {
    if (r.link) {
      const std::chrono::duration<double> silent = now - r.last_heard;
      if (silent.count() > options_.heartbeat_timeout) {
        MarkOffline(r, "no message for " + engine::FormatFixed(silent.count()) + " s (heartbeat timeout " +
                           engine::FormatFixed(options_.heartbeat_timeout) + " s)");
      }
      continue;
    }
    if (!r.offline_since || !r.has_assignment || r.assignment.order_ids.empty()) continue;
    const std::chrono::duration<double> offline = now - *r.offline_since;
    if (offline.count() < options_.offline_grace) continue;
    ServiceStatus status;
    const std::string why = "robot " + id + " offline for more than " + engine::FormatFixed(options_.offline_grace) + " s";
    auto target = [](const OrderView& v) { return engine::StateAfterRobotLoss(v.record.order.state); };
    if (ReleaseOrders(r.assignment.order_ids, target, why, &status)) {
      r.offline_since.reset();
      retry_allocation_ = true;
    }
  }
  if (retry_allocation_) allocation_due_ = true;
}

}  // namespace dispatch::server
