// The rules of a robot's stream that the dispatcher applies itself, before the dispatch core
// sees a message (dispatcher.h, "Robots"):
// - a stream starts with a Hello, and has one (OutOfTurn);
// - a second stream for a robot replaces the first only once the first has been silent for
//   the heartbeat timeout (LiveStream);
// - an ack counts only for a sequence that was sent (TakeAck);
// - a connected robot silent for longer than the heartbeat timeout goes offline
//   (SilenceTimeout), and one offline with orders for offline_grace loses them (GraceOver).
// Plain functions of a robot's session (robot_sessions.h) and its entry in the core's book.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "engine/dispatch/dispatch_core.h"
#include "server/robot_link.h"
#include "server/robot_sessions.h"

namespace dispatch::server {

// Why a message of `kind` may not come now on a stream (`hello_taken`: a Hello was taken on
// it): a second Hello, or anything before the Hello. nullopt when it may.
std::optional<std::string> OutOfTurn(RobotInbound::Kind kind, bool hello_taken);

// A Hello for `robot_id` came on a new stream while `session` has another one: why it is
// refused while that one was heard from within `heartbeat_timeout` (the robot keeps it).
// nullopt when the other stream may be superseded.
std::optional<std::string> LiveStream(const std::string& robot_id, const RobotSession& session,
                                      RobotSession::Clock::time_point now, double heartbeat_timeout);

// The robot acknowledged `sequence`. An ack of a sequence never sent is ignored: believed, it
// would skip what is sent next and (beyond 2^63) make the robot's record unstorable.
void TakeAck(RobotSession& session, std::uint64_t sequence);

// A connected robot: why it goes offline at `now` (nothing heard for longer than
// `heartbeat_timeout`); nullopt while it is heard from.
std::optional<std::string> SilenceTimeout(const RobotSession& session, RobotSession::Clock::time_point now,
                                          double heartbeat_timeout);

// A robot with no stream: why it loses its orders at `now` (it has orders, `robot` in the
// core's book, and has been offline for `offline_grace`); nullopt otherwise.
std::optional<std::string> GraceOver(const std::string& robot_id, const RobotSession& session,
                                     const engine::BookRobot* robot, RobotSession::Clock::time_point now,
                                     double offline_grace);

// The robot (null: unknown to the core) has orders in its plan: its plan is sent again when it
// reconnects, and it loses them when it stays offline.
bool HasOrders(const engine::BookRobot* robot);

}  // namespace dispatch::server
