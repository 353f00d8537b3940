// Dispatcher: carrying out the core's changes (store first, then the core, the order views and
// the robots' messages) and sending robot messages.
#include <spdlog/spdlog.h>

#include "server/change_store.h"
#include "server/dispatcher.h"

namespace dispatch::server {

storage::RobotRecord Dispatcher::RecordOf(const std::string& id) const {
  return server::RecordOf(core_->robot(id), sessions_.Find(id));
}

bool Dispatcher::Commit(const engine::Change& change, const ServerRound* round, ServiceStatus* status,
                        const std::string& actor) {
  if (change.empty()) return true;
  auto events = StoreChange(store_, change, round ? &round->details : nullptr,
                            [this](const std::string& id) { return RecordOf(id); }, actor);
  if (!events.ok()) {
    if (status) *status = FromEngineError(events.error());
    spdlog::error("{} order changes not stored, nothing changed: {}", change.orders.size(), events.error().message);
    return false;
  }
  std::vector<engine::RobotCommand> commands = core_->Apply(change);
  book_.Follow(change, round ? &round->records : nullptr);
  for (const engine::OrderChange& line : change.orders) {
    if (!line.to) continue;
    if (round && line.award < round->commit.awards.size() && options_.metrics) {
      options_.metrics->ObserveAllocation(round->commit.awards[line.award].seconds);
    }
    if (*line.to == engine::OrderState::kAssigned) spdlog::info("order {} assigned: {}", line.order_id, line.detail);
    if (*line.to == engine::OrderState::kCompleted) spdlog::info("order {} completed", line.order_id);
  }
  for (const auto& e : *events) Journal(e);
  // A robot told of an order change (a plan for a new assignment) hears of it after the
  // snapshot that holds the change: whoever it tells finds it there.
  Send(std::move(commands), /*after_publish=*/!events->empty());
  effects_.MarkChanged();
  return true;
}

void Dispatcher::Send(std::vector<engine::RobotCommand> commands, bool after_publish) {
  for (auto& c : commands) SendTo(c.robot, std::move(c.message), after_publish);
}

void Dispatcher::SendTo(const std::string& robot_id, RobotOutbound message, bool after_publish) {
  RobotSession* found = sessions_.Find(robot_id);
  if (!found) return;
  RobotSession& s = *found;
  message.sequence = s.next_sequence++;
  message.server_time = Now();
  if (!s.link) return;
  // A Welcome waits for the snapshot that holds the robot; plans, grants and holds do not,
  // unless they come with an order change.
  after_publish = after_publish || message.kind == RobotOutbound::Kind::kWelcome;
  Defer([link = s.link, message = std::move(message)]() mutable { link->Send(std::move(message)); }, after_publish);
}

}  // namespace dispatch::server
