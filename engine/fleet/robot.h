// Robots (SPEC §2): identity, size, speed, operating state, pose and assigned task queue.
//
// Invariants of a valid Robot (ValidateRobot): non-empty id, diameter > 0, max_speed > 0,
// finite pose, battery (if known) in [0, 1]. `current_point` is the point the robot stands on
// or, while moving, the next point it will reach (kNoPoint when not on the graph).
// Plain values: not thread-safe to mutate concurrently, safe to share once built.
#pragma once

#include <Eigen/Core>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "engine/common/result.h"
#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

enum class RobotState { kIdle, kMoving, kWorking, kWaiting, kParked, kCharging, kFault, kOffline };

// "idle", "moving", "working", "waiting", "parked", "charging", "fault", "offline".
const char* RobotStateName(RobotState state);
std::optional<RobotState> ParseRobotState(std::string_view name);

// How a robot moves (its Hello says): a differential drive follows the road graph; a
// four-wheel-steer (4WIS) robot follows it too, and inside the map's free-space regions the
// hybrid A*'s paths (crab, spin, steer; engine/motion/free_space_plan.h).
enum class RobotKind { kDifferential, kFourWheelSteer };
// "differential", "four_wheel_steer".
const char* RobotKindName(RobotKind kind);
std::optional<RobotKind> ParseRobotKind(std::string_view name);

struct Pose {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  // metres
  double heading = 0.0;                                // radians, counter-clockwise from +x
};

struct Robot {
  std::string id;
  RobotKind kind = RobotKind::kDifferential;
  double diameter = 0.4;   // metres (Chu2024 §4.1)
  double max_speed = 1.0;  // v, m/s
  RobotState state = RobotState::kIdle;
  Pose pose;
  PointId current_point = kNoPoint;
  std::vector<std::string> task_queue;  // order ids, in execution order
  std::optional<double> battery;        // state of charge in [0, 1], if reported
};

// kInvalidArgument naming the robot and the offending field.
Status ValidateRobot(const Robot& robot);

}  // namespace dispatch::engine
