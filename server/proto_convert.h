// Proto <-> engine/server conversions for the gRPC services: the one place per direction
// (STYLE.md). Pure functions; thread-safe.
#pragma once

#include <optional>

#include "engine/common/result.h"
#include "engine/fleet/order.h"
#include "engine/map/warehouse_map.h"
#include "server/robot_link.h"
#include "server/snapshot.h"
#include "storage/store.h"
#include "warehouse/dispatch/v1/fleet.pb.h"
#include "warehouse/dispatch/v1/map.pb.h"
#include "warehouse/dispatch/v1/orders.pb.h"

namespace dispatch::server {

namespace pb = ::warehouse::dispatch::v1;

// --- proto -> engine/server ------------------------------------------------------------
// kInvalidArgument naming the field: a stop with neither name nor position, a missing drop,
// a non-finite work time.
engine::Result<engine::OrderRequest> OrderRequestFromProto(const pb::SubmitOrderRequest& request);
std::optional<engine::OrderState> OrderStateFromProto(pb::OrderState state);
// kInvalidArgument for a message without a body.
engine::Result<RobotInbound> RobotInboundFromProto(const pb::RobotMessage& message);

// --- engine/server -> proto ------------------------------------------------------------
pb::OrderState OrderStateToProto(engine::OrderState state);
pb::WaypointAction ActionToProto(engine::WaypointAction action);
pb::MotionMode MotionModeToProto(engine::MotionMode mode);
// The point's id, name and position (only the id when it is not on the map).
void StopToProto(engine::PointId point, const engine::WarehouseMap& map, pb::ResolvedStop* out);
void OrderToProto(const OrderView& order, const engine::WarehouseMap& map, pb::Order* out);
void EventToProto(const storage::OrderEvent& event, pb::OrderEvent* out);
void AllocationToProto(const AllocationRecord& allocation, const engine::WarehouseMap& map,
                       pb::AllocationExplanation* out);
void OutboundToProto(const RobotOutbound& message, pb::ServerMessage* out);
void MapToProto(const engine::WarehouseMap& map, const std::string& version, pb::GetMapResponse* out);

}  // namespace dispatch::server
