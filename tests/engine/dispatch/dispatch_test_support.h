// Shared set-up of the dispatch core's tests: the built-in Chu2024 floor, its route table, and
// single-pick orders on it.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/fleet/order.h"

#include "engine/map/chu2024_floor.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine::testing_util {

inline std::shared_ptr<const WarehouseMap> Chu2024() {
  static const auto map = [] {
    auto built = BuildChu2024Floor();
    if (!built.ok()) throw std::runtime_error(built.error().message);
    return std::make_shared<const WarehouseMap>(std::move(built).value());
  }();
  return map;
}

inline std::shared_ptr<const RouteTable> Chu2024Routes() {
  static const std::shared_ptr<const RouteTable> routes = [] {
    RouteTableOptions options;
    auto table = MakeRouteTable(Chu2024(), options);
    if (!table.ok()) throw std::runtime_error(table.error().message);
    return std::shared_ptr<const RouteTable>(std::move(table).value());
  }();
  return routes;
}

// The floor's points of one kind, in id order.
inline std::vector<PointId> PointsOfKind(const WarehouseMap& map, PointKind kind) {
  std::vector<PointId> out;
  for (std::size_t i = 0; i < map.points().size(); ++i) {
    if (map.points()[i].kind == kind) out.push_back(static_cast<PointId>(i));
  }
  return out;
}

// A single-pick order as the core holds it.
inline std::shared_ptr<const Order> MakeOrder(const std::string& id, PointId pick, PointId drop, double created,
                                              int priority = 0) {
  auto o = std::make_shared<Order>();
  o->id = id;
  o->client_id = id;
  o->picks = {pick};
  o->drop = drop;
  o->created_time = created;
  o->priority = priority;
  return o;
}

}  // namespace dispatch::engine::testing_util
