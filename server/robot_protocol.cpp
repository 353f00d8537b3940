#include "server/robot_protocol.h"

#include <algorithm>
#include <chrono>

#include "engine/dispatch/robot_intake.h"

namespace dispatch::server {

std::optional<std::string> OutOfTurn(RobotInbound::Kind kind, bool hello_taken) {
  const bool hello = kind == RobotInbound::Kind::kHello;
  if (hello && hello_taken) return "Hello sent twice on one stream";
  if (!hello && !hello_taken) return "the first message of a stream must be Hello";
  return std::nullopt;
}

std::optional<std::string> LiveStream(const std::string& robot_id, const RobotSession& session,
                                      RobotSession::Clock::time_point now, double heartbeat_timeout) {
  const std::chrono::duration<double> silent = now - session.last_heard;
  if (silent.count() > heartbeat_timeout) return std::nullopt;
  return "robot " + robot_id + " already has a live stream (heard " + engine::FormatFixed(silent.count()) +
         " s ago); retry after its heartbeat times out";
}

void TakeAck(RobotSession& session, std::uint64_t sequence) {
  if (sequence < session.next_sequence) session.last_acked_sequence = std::max(session.last_acked_sequence, sequence);
}

std::optional<std::string> SilenceTimeout(const RobotSession& session, RobotSession::Clock::time_point now,
                                          double heartbeat_timeout) {
  const std::chrono::duration<double> silent = now - session.last_heard;
  if (silent.count() <= heartbeat_timeout) return std::nullopt;
  return "no message for " + engine::FormatFixed(silent.count()) + " s (heartbeat timeout " +
         engine::FormatFixed(heartbeat_timeout) + " s)";
}

std::optional<std::string> GraceOver(const std::string& robot_id, const RobotSession& session,
                                     const engine::BookRobot* robot, RobotSession::Clock::time_point now,
                                     double offline_grace) {
  if (!session.offline_since || !HasOrders(robot)) return std::nullopt;
  const std::chrono::duration<double> offline = now - *session.offline_since;
  if (offline.count() < offline_grace) return std::nullopt;
  return "robot " + robot_id + " offline for more than " + engine::FormatFixed(offline_grace) + " s";
}

bool HasOrders(const engine::BookRobot* robot) {
  return robot && robot->has_assignment && !robot->assignment.order_ids.empty();
}

}  // namespace dispatch::server
