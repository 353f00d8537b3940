#include "engine/fleet/robot.h"

#include <cmath>

namespace dispatch::engine {

const char* RobotStateName(RobotState state) {
  switch (state) {
    case RobotState::kIdle: return "idle";
    case RobotState::kMoving: return "moving";
    case RobotState::kWorking: return "working";
    case RobotState::kWaiting: return "waiting";
    case RobotState::kParked: return "parked";
    case RobotState::kCharging: return "charging";
    case RobotState::kFault: return "fault";
    case RobotState::kOffline: return "offline";
  }
  return "unknown";
}

std::optional<RobotState> ParseRobotState(std::string_view name) {
  for (RobotState s : {RobotState::kIdle, RobotState::kMoving, RobotState::kWorking,
                       RobotState::kWaiting, RobotState::kParked, RobotState::kCharging,
                       RobotState::kFault, RobotState::kOffline}) {
    if (name == RobotStateName(s)) return s;
  }
  return std::nullopt;
}

const char* RobotKindName(RobotKind kind) {
  return kind == RobotKind::kFourWheelSteer ? "four_wheel_steer" : "differential";
}

std::optional<RobotKind> ParseRobotKind(std::string_view name) {
  for (RobotKind k : {RobotKind::kDifferential, RobotKind::kFourWheelSteer}) {
    if (name == RobotKindName(k)) return k;
  }
  return std::nullopt;
}

Status ValidateRobot(const Robot& robot) {
  if (robot.id.empty()) return InvalidArgument("robot id is empty");
  const std::string who = "robot '" + robot.id + "': ";
  if (!std::isfinite(robot.diameter) || robot.diameter <= 0.0) {
    return InvalidArgument(who + "diameter must be > 0 m, got " + std::to_string(robot.diameter));
  }
  if (!std::isfinite(robot.max_speed) || robot.max_speed <= 0.0) {
    return InvalidArgument(who + "max speed must be > 0 m/s, got " +
                           std::to_string(robot.max_speed));
  }
  if (!robot.pose.position.allFinite() || !std::isfinite(robot.pose.heading)) {
    return InvalidArgument(who + "pose is not finite");
  }
  if (robot.battery && !(*robot.battery >= 0.0 && *robot.battery <= 1.0)) {
    return InvalidArgument(who + "battery must be in [0, 1], got " +
                           std::to_string(*robot.battery));
  }
  return Ok{};
}

}  // namespace dispatch::engine
