// Shared set-up of the dispatch core's tests: the built-in Chu2024 floor, its route table, and
// single-pick orders on it.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/dispatch/dispatch_core.h"
#include "engine/dispatch/strategy.h"
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

// A dispatch core on the floor (throws on an error: a bad test set-up).
inline std::unique_ptr<DispatchCore> Chu2024Core(CoreOptions options) {
  auto core = DispatchCore::Create(Chu2024(), Chu2024Routes(), options);
  if (!core.ok()) throw std::runtime_error(core.error().message);
  return std::move(core).value();
}

// Allocation rounds on the floor with the auction.
inline std::unique_ptr<RoundRunner> AuctionRounds() {
  auto allocator = MakeAllocator("auction");
  if (!allocator.ok()) throw std::runtime_error(allocator.error().message);
  return std::make_unique<RoundRunner>(Chu2024(), Chu2024Routes(), AllocationConfig{}, std::move(allocator).value());
}

// Robot `id` says Hello standing at point `at` (its plan messages, if any, are dropped).
inline void ConnectAt(DispatchCore& core, const std::string& id, PointId at, double now) {
  Robot r;
  r.id = id;
  r.current_point = at;
  r.pose.position = Chu2024()->point(at).position;
  (void)core.Connect(std::move(r), now);
}

// One allocation round, every award applied; false when there was nothing to allocate (no
// accepted order, or no robot that may bid).
inline bool ApplyRound(DispatchCore& core, RoundRunner& rounds, double now) {
  RoundCommit commit;
  std::optional<RoundInput> input = core.MakeRound(now, commit);
  if (!input) return false;
  commit.awards = rounds.Run(*input).awards;
  (void)core.Apply(core.PlanAwards(commit, commit.awards.size(), now));
  return true;
}

// The floor's points of one kind, in id order.
inline std::vector<PointId> PointsOfKind(const WarehouseMap& map, PointKind kind) {
  std::vector<PointId> out;
  for (std::size_t i = 0; i < map.points().size(); ++i) {
    if (map.points()[i].kind == kind) out.push_back(static_cast<PointId>(i));
  }
  return out;
}

// The floor's parking, pick and drop points, each in id order (PointsOfKind).
struct FloorStops {
  std::vector<PointId> parks, picks, drops;
};
inline FloorStops StopsOfFloor(const WarehouseMap& map) {
  return {PointsOfKind(map, PointKind::kPark), PointsOfKind(map, PointKind::kPick), PointsOfKind(map, PointKind::kDrop)};
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
