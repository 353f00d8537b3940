// What the traffic prediction's tests share: the reference zone lookup.
#pragma once

#include <Eigen/Core>

#include <cstddef>

#include "engine/map/warehouse_map.h"

namespace dispatch::engine::testing_zones {

// The reference ZoneAt: the lowest zone id whose Contains holds (-1: none).
inline ZoneId BruteForceZone(const WarehouseMap& map, const Eigen::Vector2d& xy) {
  for (std::size_t z = 0; z < map.zones().size(); ++z) {
    if (map.zones()[z].Contains(xy)) return static_cast<ZoneId>(z);
  }
  return -1;
}

}  // namespace dispatch::engine::testing_zones
