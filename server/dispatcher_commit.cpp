// Dispatcher: carrying out the core's changes (store first, then the core, the order views and
// the robots' messages) and sending robot messages.
#include <spdlog/spdlog.h>

#include "server/dispatcher.h"

namespace dispatch::server {

storage::RobotRecord Dispatcher::RecordOf(const std::string& id) const {
  storage::RobotRecord rec;
  if (const engine::BookRobot* r = core_->robot(id)) rec.robot = r->robot;
  if (auto it = sessions_.find(id); it != sessions_.end()) {
    rec.kind = it->second.kind;
    rec.last_seen = it->second.last_seen;
    rec.last_acked_sequence = it->second.last_acked_sequence;
    rec.next_sequence = it->second.next_sequence;
  }
  return rec;
}

bool Dispatcher::Commit(const engine::Change& change, const ServerRound* round, ServiceStatus* status) {
  if (change.empty()) return true;
  const double now = change.time;
  const std::map<std::string, std::uint64_t> messages = change.MessageCounts();
  std::set<std::string> robots;  // records to store: new plans (their queue), reserved sequences
  for (const auto& [id, plan] : change.plans) robots.insert(id);
  for (const auto& [id, n] : messages) robots.insert(id);
  std::vector<storage::OrderEvent> events;
  auto committed = store_.RunInTransaction([&](storage::Store& s) -> engine::Status {
    events.clear();
    for (const engine::OrderChange& line : change.orders) {
      if (line.to) {
        storage::OrderTransition t;
        t.order_id = line.order_id;
        t.to = *line.to;
        t.time = now;
        t.robots = line.robots;
        t.detail = line.detail;
        t.distance = line.distance;
        auto e = s.TransitionOrder(t);
        if (!e.ok()) return e.error();
        events.push_back(*e);
      } else {
        auto e = s.AppendProgress(line.order_id, now, line.detail);
        if (!e.ok()) return e.error();
        events.push_back(*e);
      }
      if (round && line.award < round->details.size()) {
        auto e = s.AppendProgress(line.order_id, now, round->details[line.award]);
        if (!e.ok()) return e.error();
        events.push_back(*e);
      }
    }
    for (const auto& [id, plan] : change.plans) {
      if (auto saved = s.SaveAssignment(plan); !saved.ok()) return saved.error();
    }
    for (const auto& id : robots) {
      storage::RobotRecord rec = RecordOf(id);
      if (auto plan = change.plans.find(id); plan != change.plans.end()) rec.robot.task_queue = plan->second.order_ids;
      if (auto n = messages.find(id); n != messages.end()) rec.next_sequence += n->second;
      if (auto saved = s.UpsertRobot(rec); !saved.ok()) return saved.error();
    }
    return engine::Ok{};
  });
  if (!committed.ok()) {
    if (status) *status = FromEngineError(committed.error());
    spdlog::error("{} order changes not stored, nothing changed: {}", change.orders.size(), committed.error().message);
    return false;
  }
  std::vector<engine::RobotCommand> commands = core_->Apply(change);
  // The order views follow the same lines.
  for (const engine::OrderChange& line : change.orders) {
    auto found = book_.Find(line.order_id);
    if (!found) continue;
    auto view = std::make_shared<OrderView>(*found);
    if (auto d = change.dropped_by.find(line.order_id); d != change.dropped_by.end()) view->dropped_by = d->second;
    if (line.to) {
      const engine::OrderState to = *line.to;
      view->record.order.state = to;
      view->record.updated_time = now;
      if (line.robots) view->record.robots = *line.robots;
      if (line.distance) view->record.distance = *line.distance;
      if (engine::IsTerminal(to)) view->finished_time = now;
      if (to == engine::OrderState::kCancelled || to == engine::OrderState::kFailed) view->record.reason = line.detail;
      if (round && line.award < round->records.size()) {
        view->explanation = round->records[line.award];
        if (options_.metrics) options_.metrics->ObserveAllocation(round->commit.awards[line.award].seconds);
      }
      if (to == engine::OrderState::kAssigned) spdlog::info("order {} assigned: {}", line.order_id, line.detail);
      if (to == engine::OrderState::kCompleted) spdlog::info("order {} completed", line.order_id);
    }
    book_.Put(std::move(view));
  }
  for (const auto& e : events) Journal(e);
  Send(std::move(commands));
  dirty_ = true;
  return true;
}

void Dispatcher::Send(std::vector<engine::RobotCommand> commands) {
  for (auto& c : commands) SendTo(c.robot, std::move(c.message));
}

void Dispatcher::SendTo(const std::string& robot_id, RobotOutbound message) {
  auto it = sessions_.find(robot_id);
  if (it == sessions_.end()) return;
  RobotSession& s = it->second;
  message.sequence = s.next_sequence++;
  message.server_time = Now();
  if (!s.link) return;
  // A Welcome waits for the snapshot that holds the robot; plans, grants and holds do not.
  const bool after_publish = message.kind == RobotOutbound::Kind::kWelcome;
  Defer([link = s.link, message = std::move(message)]() mutable { link->Send(std::move(message)); }, after_publish);
}

}  // namespace dispatch::server
