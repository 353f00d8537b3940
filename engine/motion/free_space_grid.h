// The occupancy grid of one free-space region of a map (issue 17 §3, map_format.md "free
// space"): the region's bounding box at `resolution` metres per cell, a cell free when its
// centre lies in the region's polygon (boundary included) and no shelf covers any of it —
// what the hybrid A* (hybrid_astar.h) searches when it plans a four-wheel-steer robot inside
// the region. Clearance computed. Errors: kNotFound (no such region), kInvalidArgument
// (resolution <= 0, or over 10^8 cells).
#pragma once

#include <cstddef>

#include "engine/common/result.h"
#include "engine/map/warehouse_map.h"
#include "engine/motion/occupancy_grid.h"

namespace dispatch::engine {

Result<OccupancyGrid> FreeSpaceGrid(const WarehouseMap& map, std::size_t region, double resolution);

}  // namespace dispatch::engine
