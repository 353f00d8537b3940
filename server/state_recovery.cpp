#include "server/state_recovery.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <map>
#include <optional>
#include <string>
#include <utility>

namespace dispatch::server {

engine::Result<RecoveredState> RecoverState(storage::Store& store, bool traffic_control, OrderViews& book,
                                            engine::JournaledCore& core, RobotSessions& sessions,
                                            RestartWait& restart_wait) {
  RecoveredState out;
  auto loaded = book.Load(store);
  if (!loaded.ok()) return loaded.error();
  out.latest_time = std::max(out.latest_time, loaded->latest_time);
  out.last_order_number = std::max(out.last_order_number, loaded->last_order_number);
  // The open orders enter the core with their robots.
  for (const auto& view : book.all()) {
    const storage::OrderRecord& rec = view->record;
    if (!engine::IsTerminal(rec.order.state)) core.AddOrder(rec.order, rec.robots);
  }
  // Robots (all offline until they reconnect) and their plans.
  auto robots = store.ListRobots();
  if (!robots.ok()) return robots.error();
  auto assignments = store.ListAssignments();
  if (!assignments.ok()) return assignments.error();
  std::map<std::string, engine::Assignment> plans;
  for (auto& a : *assignments) {
    out.latest_time = std::max(out.latest_time, a.updated_time);
    plans[a.robot_id] = std::move(a);
  }
  for (auto& record : *robots) {
    const std::string id = record.robot.id;
    RobotSession& s = sessions.Get(id);
    RestoreSession(s, record);
    s.offline_since = RobotSession::Clock::now();
    out.latest_time = std::max(out.latest_time, record.last_seen);
    // On line when the old process stopped: where it is now is known when it reports.
    const bool was_on_line = traffic_control && record.robot.state != engine::RobotState::kOffline;
    if (was_on_line) restart_wait.Await(id);
    auto plan = plans.find(id);
    core.RestoreRobot(std::move(record.robot),
                      plan == plans.end() ? std::nullopt : std::optional<engine::Assignment>(std::move(plan->second)),
                      !was_on_line, std::move(record.marks));
  }
  std::uint64_t retired = 0;
  for (const auto& [state, n] : book.finished_in_store()) retired += n;
  spdlog::info("recovered {} orders ({} finished ones left in the store), {} robots, {} assignments; "
               "dispatcher time {:.1f} s", book.all().size(), retired, sessions.size(), plans.size(), out.latest_time);
  return out;
}

}  // namespace dispatch::server
