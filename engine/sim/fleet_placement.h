// Where a simulated fleet starts: robots R1..Rn at the map's parking stations in station
// order, then (maps with too few stations, e.g. imported grids) at lane points spread evenly
// over the point list. Errors: count 0, or more robots than stations + lane points.
// Pure function; thread-safe.
#pragma once

#include <cstddef>
#include <vector>

#include "engine/allocation/fleet_state.h"
#include "engine/common/result.h"
#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

Result<std::vector<FleetRobot>> PlaceRobots(const WarehouseMap& map, std::size_t count);

}  // namespace dispatch::engine
