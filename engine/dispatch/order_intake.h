// Order intake: the one place an order request is validated and resolved (issue 15 §1), for the
// service (gRPC and REST alike) and the simulator. The adapters map the one Error it returns:
// kInvalidArgument / kNotFound / kUnreachable are the caller's fault (gRPC INVALID_ARGUMENT,
// HTTP 400), with a message naming the order by its client id and what was wrong.
//
// Pure functions of their arguments; thread-safe (RouteTable::Cost is).
#pragma once

#include <cstddef>
#include <vector>

#include "engine/common/result.h"
#include "engine/fleet/order.h"
#include "engine/map/warehouse_map.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine {

// Picks per order. Seed tasks have 1-3; the cap keeps one order (and so every page of orders
// and every plan carrying it) far below gRPC's 4 MiB message limit.
inline constexpr std::size_t kMaxPicksPerOrder = 100;
// Bytes of a client order id (the idempotency key).
inline constexpr std::size_t kMaxClientIdBytes = 128;

// Checks the request (client id present and at most kMaxClientIdBytes, at most
// kMaxPicksPerOrder picks), resolves its stops (ResolveOrder: snapping, work and release
// times) and checks that the route pick 1 -> ... -> drop exists. The order keeps
// request.created_time; its id is `order_id`.
Result<Order> AdmitOrder(const WarehouseMap& map, const RouteTable& routes, const OrderRequest& request,
                         const SnapOptions& snap, const std::string& order_id);

// The stops (picks, then the drop) the request resolves to; empty when it does not resolve.
std::vector<PointId> StopsOf(const WarehouseMap& map, const OrderRequest& request, const SnapOptions& snap);

}  // namespace dispatch::engine
