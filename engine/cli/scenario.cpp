#include "engine/cli/scenario.h"

#include <fstream>
#include <sstream>

#include "engine/fleet/task_table.h"

namespace dispatch::engine {

Result<std::vector<Order>> LoadTaskTableOrders(const WarehouseMap& map, const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return IoError("cannot read task table '" + path + "'");
  std::stringstream text;
  text << in.rdbuf();
  auto requests = ParseTaskTable(text.str());
  if (!requests.ok()) return Error{requests.error().code, path + ": " + requests.error().message};
  std::vector<Order> orders;
  for (std::size_t i = 0; i < requests->size(); ++i) {
    OrderRequest request = (*requests)[i];
    request.id = "T" + request.id;
    if (request.client_id.empty()) request.client_id = request.id;
    request.created_time = static_cast<double>(i);
    auto order = ResolveOrder(map, request);
    if (!order.ok()) {
      return Error{order.error().code, path + ": task " + request.id + ": " + order.error().message};
    }
    orders.push_back(std::move(order).value());
  }
  return orders;
}

Result<std::vector<FleetRobot>> RobotsAtStations(const WarehouseMap& map, std::size_t count) {
  const auto& stations = map.stations();
  if (stations.empty()) return InvalidArgument("map '" + map.name() + "' has no parking stations");
  if (count == 0) count = stations.size();
  if (count > stations.size()) {
    return InvalidArgument("map '" + map.name() + "' has " + std::to_string(stations.size()) +
                           " parking stations, fewer than " + std::to_string(count) + " robots");
  }
  std::vector<FleetRobot> robots;
  for (std::size_t i = 0; i < count; ++i) {
    robots.push_back({"R" + std::to_string(i + 1), stations[i].point, 0.0});
  }
  return robots;
}

}  // namespace dispatch::engine
