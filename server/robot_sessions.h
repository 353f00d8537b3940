// RobotSessions: what the service keeps of each robot besides the dispatch core's book - its
// stream (RobotLink), the message sequences of the robot protocol, when it was last heard and
// since when it is offline - and which stream belongs to which robot. A robot's record as
// stored (storage::RobotRecord) is the core's robot plus its session (RecordOf), and a Hello
// updates that record in one place (HelloRecord). TrackHold times the traffic holds.
//
// Not thread-safe: the dispatcher's loop owns it.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>

#include "engine/dispatch/dispatch_core.h"
#include "server/robot_link.h"
#include "storage/store.h"

namespace dispatch::server {

struct RobotSession {
  using Clock = std::chrono::steady_clock;
  std::string kind;                       // drive kinematics, e.g. "differential"
  double last_seen = 0.0;                 // dispatcher seconds of its last message
  std::uint64_t last_acked_sequence = 0;  // server message sequence it acknowledged
  std::uint64_t next_sequence = 1;        // next server message sequence to use
  std::shared_ptr<RobotLink> link;        // null when not connected
  Clock::time_point last_heard;
  std::optional<Clock::time_point> offline_since;  // set while offline with orders to watch
  std::optional<double> held_since;                // dispatcher seconds of the Hold in force
};

class RobotSessions {
 public:
  using Map = std::map<std::string, RobotSession>;

  RobotSession* Find(const std::string& robot_id);
  const RobotSession* Find(const std::string& robot_id) const;
  // The session of `robot_id`, a new one if it has none.
  RobotSession& Get(const std::string& robot_id) { return sessions_[robot_id]; }
  // The robot whose stream `link` is (a Hello was taken on it); nullptr otherwise.
  const std::string* RobotOf(const RobotLink* link) const;
  // `link` becomes the robot's stream.
  void Attach(const std::string& robot_id, std::shared_ptr<RobotLink> link);
  // Takes the robot's stream away and returns it (to be closed); nullptr when it had none.
  std::shared_ptr<RobotLink> Detach(const std::string& robot_id);
  // Forgets which robot `link` was (the stream ended).
  void Forget(const RobotLink* link) { link_robot_.erase(link); }

  Map::iterator begin() { return sessions_.begin(); }
  Map::iterator end() { return sessions_.end(); }
  Map::const_iterator begin() const { return sessions_.begin(); }
  Map::const_iterator end() const { return sessions_.end(); }
  std::size_t size() const { return sessions_.size(); }

 private:
  Map sessions_;
  std::unordered_map<const RobotLink*, std::string> link_robot_;
};

// A traffic message about to go to the robot: a Hold starts its wait (unless one is in force
// already), a Grant or Resume ends it. Returns how long it stood held (dispatcher seconds,
// dispatch_grant_wait_seconds) when this message ended a wait.
std::optional<double> TrackHold(RobotSession& session, RobotOutbound::Kind kind, double now);
// The robot as stored: the core's robot (if it knows it) and its session (if any).
storage::RobotRecord RecordOf(const engine::BookRobot* robot, const RobotSession* session);
// The session's part of a stored record (recovery).
void RestoreSession(RobotSession& session, const storage::RobotRecord& record);
// What a Hello makes of the robot's record: its pose and point, the size and speed it states
// (the allocation's speed when it states none), idle, seen now, and message sequences that
// continue after what it acknowledged; back on the floor if an operator had cleared it off. The
// caller validates the robot.
storage::RobotRecord HelloRecord(storage::RobotRecord record, const RobotInbound& hello, engine::PointId point,
                                 double default_speed, double now);

}  // namespace dispatch::server
