// Robot intake (issue 15 §1): the one check of a robot that introduces itself (its id and the
// pose it says it stands at) and of the poses it reports later, for the service and the
// simulator. Errors are kInvalidArgument with a message naming the robot and what was wrong.
//
// Pure functions of their arguments; thread-safe.
#pragma once

#include <Eigen/Core>

#include <string>

#include "engine/common/result.h"
#include "engine/fleet/robot.h"
#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

// 1-64 letters, digits, '_', '-' or '.'.
bool ValidRobotId(const std::string& id);

// The map point a robot at `pose` stands for: the nearest point within `tolerance` metres, else
// the point it drives to on the nearest lane within `tolerance` (a robot that stopped between
// two points, e.g. when its stream broke). Errors: an invalid id, a pose that is not finite, a
// pose off the map (the message gives the nearest point and lane and their distances).
Result<PointId> LocateRobot(const WarehouseMap& map, const std::string& robot_id, const Pose& pose,
                            double tolerance);

// Finite and on the floor rectangle, give or take `margin` metres: a reported position that
// can be news about the robot (NaN, 1e300 or a wrong frame is not).
bool OnFloor(const WarehouseMap& map, const Eigen::Vector2d& xy, double margin);

// "12.35", or "1e+300" for values beyond 1e9 (not 300 digits): numbers in messages.
std::string FormatFixed(double v);

}  // namespace dispatch::engine
