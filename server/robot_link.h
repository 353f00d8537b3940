// The dispatcher's view of one robot stream (FleetService.Connect), independent of gRPC:
// what a robot says (RobotInbound) and what the dispatcher tells it (RobotOutbound), already
// converted from/to proto by the fleet service (server/proto_convert.h).
//
// RobotLink is implemented by the stream's session. Send and Close are thread-safe, never
// block and may be called after the stream ended (they then do nothing).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "engine/dispatch/robot_message.h"
#include "engine/fleet/plan.h"
#include "engine/fleet/robot.h"
#include "server/service_status.h"

namespace dispatch::server {

struct RobotInbound {
  enum class Kind { kHello, kState, kWaypointReached, kTaskEvent, kHeartbeat, kAck };
  Kind kind = Kind::kHeartbeat;
  // kHello
  std::string robot_id;
  std::string robot_kind;  // "differential", "four_wheel_steer"
  std::uint64_t last_acked_sequence = 0;
  double diameter = 0.0;   // 0 = default
  double max_speed = 0.0;  // 0 = default
  // kHello, kState, kWaypointReached
  engine::Pose pose;
  bool has_pose = true;  // kWaypointReached: the robot sent its pose with the arrival
  // kState
  std::optional<int> arc_id;
  double arc_offset = 0.0;
  double speed = 0.0;
  std::optional<engine::RobotState> state;
  std::optional<double> battery;
  std::string message;
  // kWaypointReached (waypoint sequence), kTaskEvent (its waypoint), kAck (server sequence)
  std::uint64_t sequence = 0;
  // kTaskEvent
  std::string order_id;
  bool dropped = false;  // false: picked
  int point_id = -1;
};

// What the dispatcher tells a robot: the core's message (engine/dispatch/robot_message.h).
using OutboundWaypoint = engine::MessageWaypoint;
using RobotOutbound = engine::RobotMessage;

class RobotLink {
 public:
  virtual ~RobotLink() = default;
  virtual void Send(RobotOutbound message) = 0;
  // Ends the stream with `status` (OK for a normal end).
  virtual void Close(ServiceStatus status) = 0;
};

}  // namespace dispatch::server
