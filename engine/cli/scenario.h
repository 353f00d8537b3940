// Scenario loading for the offline tools and reproduction tests: the seed's task tables
// resolved onto a map as Orders, and one robot per parking station (R<i> in the i-th
// station, as in Chu2024 §4.1: 18 robots, one per station at start).
// Reads files; not for use inside the engine's algorithms. Stateless; thread-safe.
#pragma once

#include <string>
#include <vector>

#include "engine/allocation/fleet_state.h"
#include "engine/common/result.h"
#include "engine/fleet/order.h"
#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

// Reads a task table file (engine/fleet/task_table.h format) and resolves every row onto
// `map`. Order ids are "T<task>"; created_time is the row's index, so the table's order is
// the auction's arrival order. Errors name the file and the task.
Result<std::vector<Order>> LoadTaskTableOrders(const WarehouseMap& map, const std::string& path);

// Robots R1..Rn at the map's parking stations in station order; `count` 0 = one per station.
// Error when the map has no stations or fewer than `count`.
Result<std::vector<FleetRobot>> RobotsAtStations(const WarehouseMap& map, std::size_t count = 0);

}  // namespace dispatch::engine
