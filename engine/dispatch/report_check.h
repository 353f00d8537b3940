// What a robot reports is trusted only as far as it is plausible (issue 15 §3b): an arrival
// counts only at a waypoint of the robot's current plan that was released to it, with the pose
// it reported (if any) near that waypoint; a pick or drop counts only when the robot has
// reached that order's pick or drop waypoint and stands there. Whatever is not taken is
// flagged by the caller (logged and counted), never applied.
//
// Pure functions; thread-safe.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <string>

#include "engine/dispatch/assignment.h"

namespace dispatch::engine {

struct ReportVerdict {
  bool taken = false;
  // Not taken yet: the robot has not reported reaching the stop (a drop repeated right after a
  // restart, before its first progress report). It may count once the robot reports progress.
  bool later = false;
  std::size_t index = 0;  // taken: the waypoint's index in the plan
  std::string why;        // not taken: what was implausible
};

// "Reached waypoint `seq`": in the plan, released (seq <= released_up_to), and `pose`, when the
// robot sent one, within `tolerance` metres of the waypoint.
ReportVerdict CheckReached(const Assignment& a, std::uint64_t seq, std::uint64_t released_up_to,
                           const std::optional<Eigen::Vector2d>& pose, double tolerance);

// "Picked" / "dropped" for `order_id`: the robot's plan holds a pick (drop) waypoint of that
// order with seq <= last_reached (the latest such one is the stop), and `robot_xy`, where it
// was last seen, is within `tolerance` of it. `later` when no such waypoint is reached yet.
ReportVerdict CheckTaskEvent(const Assignment& a, const std::string& order_id, bool dropped,
                             std::uint64_t last_reached, const Eigen::Vector2d& robot_xy, double tolerance);

}  // namespace dispatch::engine
