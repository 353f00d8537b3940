#include "engine/dispatch/order_intake.h"

#include <cmath>
#include <string>

namespace dispatch::engine {

Result<Order> AdmitOrder(const WarehouseMap& map, const RouteTable& routes, const OrderRequest& request,
                         const SnapOptions& snap, const std::string& order_id) {
  if (request.client_id.empty()) return InvalidArgument("client_order_id is required");
  if (request.client_id.size() > kMaxClientIdBytes) {
    return InvalidArgument("client_order_id is longer than " + std::to_string(kMaxClientIdBytes) + " bytes");
  }
  if (request.picks.size() > kMaxPicksPerOrder) {
    return InvalidArgument("order '" + request.client_id + "' has " + std::to_string(request.picks.size()) +
                           " picks; at most " + std::to_string(kMaxPicksPerOrder) + " are allowed");
  }
  OrderRequest named = request;
  named.id = request.client_id;  // errors name the order by the client's id
  auto resolved = ResolveOrder(map, named, snap);
  if (!resolved.ok()) return resolved.error();
  Order order = std::move(resolved).value();
  order.id = order_id;
  std::vector<PointId> stops = order.picks;
  stops.push_back(order.drop);
  for (std::size_t i = 0; i + 1 < stops.size(); ++i) {
    if (!std::isfinite(routes.Cost(stops[i], stops[i + 1]))) {
      const auto& a = map.point(stops[i]);
      const auto& b = map.point(stops[i + 1]);
      return InvalidArgument("order '" + order.client_id + "': no route from " + PointKindName(a.kind) +
                             " point '" + a.name + "' to " + PointKindName(b.kind) + " point '" + b.name + "'");
    }
  }
  return order;
}

std::vector<PointId> StopsOf(const WarehouseMap& map, const OrderRequest& request, const SnapOptions& snap) {
  if (request.picks.size() > kMaxPicksPerOrder) return {};
  auto resolved = ResolveOrder(map, request, snap);
  if (!resolved.ok()) return {};
  std::vector<PointId> stops = resolved->picks;
  stops.push_back(resolved->drop);
  return stops;
}

}  // namespace dispatch::engine
