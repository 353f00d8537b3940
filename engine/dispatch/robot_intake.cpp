#include "engine/dispatch/robot_intake.h"

#include "engine/common/text.h"

#include <cctype>
#include <cmath>
#include <sstream>

namespace dispatch::engine {

bool ValidRobotId(const std::string& id) {
  if (id.empty() || id.size() > 64) return false;
  for (char c : id) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) return false;
  }
  return true;
}

std::string FormatFixed(double v) {
  std::ostringstream out;
  if (std::abs(v) < 1e9) {
    out.precision(2);
    out << std::fixed;
  }
  out << v;
  return out.str();
}

Result<PointId> LocateRobot(const WarehouseMap& map, const std::string& robot_id, const Pose& pose,
                            double tolerance) {
  if (!ValidRobotId(robot_id)) {
    return InvalidArgument("robot id '" + Clipped(robot_id) + "' is invalid: use 1-64 letters, digits, '_', '-' or '.'");
  }
  const Eigen::Vector2d& xy = pose.position;
  if (!xy.allFinite() || !std::isfinite(pose.heading)) {
    return InvalidArgument("robot " + robot_id + ": pose is not finite");
  }
  double distance = 0.0;
  PointId point = map.NearestPoint(xy, std::nullopt, &distance);
  if (point != kNoPoint && distance <= tolerance) return point;
  double lane_distance = 0.0;
  auto on_lane = map.NearestArcPosition(xy, &lane_distance);
  if (on_lane.ok() && lane_distance <= tolerance) return map.arc(on_lane->arc).to;
  const std::string nearest =
      point == kNoPoint ? "none" : "'" + map.point(point).name + "' " + FormatFixed(distance) + " m away";
  return InvalidArgument("robot " + robot_id + ": pose (" + FormatFixed(xy.x()) + ", " + FormatFixed(xy.y()) +
                         ") is not on the map (nearest point " + nearest + ", nearest lane " +
                         (on_lane.ok() ? FormatFixed(lane_distance) + " m away" : std::string("none")) +
                         ", tolerance " + FormatFixed(tolerance) + " m)");
}

bool OnFloor(const WarehouseMap& map, const Eigen::Vector2d& xy, double margin) {
  return xy.allFinite() && xy.x() >= map.floor_min().x() - margin && xy.x() <= map.floor_max().x() + margin &&
         xy.y() >= map.floor_min().y() - margin && xy.y() <= map.floor_max().y() + margin;
}

}  // namespace dispatch::engine
