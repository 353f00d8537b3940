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

// A waypoint as sent: the engine waypoint (seq = the robot's life-long waypoint sequence)
// plus the order it serves and whether the robot may drive to it.
struct OutboundWaypoint {
  engine::Waypoint waypoint;
  std::string order_id;
  bool released = true;
};

struct RobotOutbound {
  enum class Kind { kWelcome, kAssignment, kPlanUpdate, kCancel, kGrant, kHold, kResume };
  Kind kind = Kind::kWelcome;
  std::uint64_t sequence = 0;
  double server_time = 0.0;
  // kWelcome
  double time_scale = 1.0;
  double heartbeat_interval = 1.0;
  double heartbeat_timeout = 5.0;
  std::uint64_t resume_from_sequence = 1;
  std::string map_version;
  // kAssignment, kPlanUpdate
  std::uint64_t plan_id = 0;
  std::uint64_t from_sequence = 0;  // kPlanUpdate
  std::vector<std::string> order_ids;
  std::vector<OutboundWaypoint> waypoints;
  std::uint64_t released_up_to = 0;
  std::vector<std::string> formation_members;
  // kCancel (order_ids above: the cancelled orders), kHold: why
  std::string reason;
  // kGrant (released_up_to above: the new horizon; intersection -1 for a plain lane release),
  // kResume (released_up_to above)
  int intersection_id = -1;
  std::string intersection_name;
  // kHold: stop at this waypoint sequence (0: at once)
  std::uint64_t stop_at_sequence = 0;
};

class RobotLink {
 public:
  virtual ~RobotLink() = default;
  virtual void Send(RobotOutbound message) = 0;
  // Ends the stream with `status` (OK for a normal end).
  virtual void Close(ServiceStatus status) = 0;
};

}  // namespace dispatch::server
