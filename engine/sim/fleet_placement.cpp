#include "engine/sim/fleet_placement.h"

#include <string>

namespace dispatch::engine {

Result<std::vector<FleetRobot>> PlaceRobots(const WarehouseMap& map, std::size_t count) {
  if (count == 0) return InvalidArgument("place robots: need at least one robot");
  std::vector<FleetRobot> robots;
  for (const ParkingStation& s : map.stations()) {
    if (robots.size() == count) break;
    robots.push_back({"R" + std::to_string(robots.size() + 1), s.point, 0.0});
  }
  if (robots.size() == count) return robots;
  std::vector<PointId> lanes;
  for (std::size_t p = 0; p < map.point_count(); ++p) {
    if (map.points()[p].kind == PointKind::kLane) lanes.push_back(static_cast<PointId>(p));
  }
  const std::size_t need = count - robots.size();
  if (lanes.size() < need) {
    return InvalidArgument("place robots: map '" + map.name() + "' has room for " +
                           std::to_string(robots.size() + lanes.size()) + " robots, not " +
                           std::to_string(count));
  }
  for (std::size_t i = 0; i < need; ++i) {
    const PointId p = lanes[i * lanes.size() / need];
    robots.push_back({"R" + std::to_string(robots.size() + 1), p, 0.0});
  }
  return robots;
}

}  // namespace dispatch::engine
