// What the dispatch core tells a robot (issue 15 §1: outputs are values): its plan (the whole
// Assignment, or a PlanUpdate from a waypoint on), a Cancel of orders taken away, and the traffic
// gate's Grant, Hold and Resume. The owner stamps the message sequence and time and carries it
// (the service over its gRPC stream, server/proto_convert.h; the simulator to its motion model).
// kWelcome is the session's greeting, made by the service only.
//
// Plain values.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "engine/fleet/plan.h"

namespace dispatch::engine {

// A waypoint as sent: the engine waypoint (seq = the robot's life-long waypoint sequence)
// plus the order it serves and whether the robot may drive to it.
struct MessageWaypoint {
  Waypoint waypoint;
  std::string order_id;
  bool released = true;
};

struct RobotMessage {
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
  std::vector<MessageWaypoint> waypoints;
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

}  // namespace dispatch::engine
