// JSON views of the dispatcher's state for REST and the journal (one place for engine/server
// types -> JSON and back). The allocation explanation is journaled as a progress event whose
// detail is "allocation: " + JSON, so it survives restarts. Pure functions; thread-safe.
#pragma once

#include <nlohmann/json.hpp>

#include <optional>
#include <string>

#include "engine/map/warehouse_map.h"
#include "server/snapshot.h"

namespace dispatch::server {

inline constexpr const char* kAllocationDetailPrefix = "allocation: ";

std::string AllocationDetail(const AllocationRecord& allocation);
// nullopt when `detail` is not an allocation detail (or is corrupt).
std::optional<AllocationRecord> ParseAllocationDetail(const std::string& detail);

nlohmann::json AllocationToJson(const AllocationRecord& allocation, const engine::WarehouseMap& map);
// id, client_id, state (lower case), robots, priority, picks, drop, formation, work_time,
// created_time, finished_time, reason; with `explain` also "allocation".
nlohmann::json OrderToJson(const OrderView& order, const engine::WarehouseMap& map, bool explain);
nlohmann::json RobotToJson(const RobotView& robot, const engine::WarehouseMap& map);
nlohmann::json StopToJson(engine::PointId point, const engine::WarehouseMap& map);

}  // namespace dispatch::server
