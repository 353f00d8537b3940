// Helpers of the order-stream tests on the dispatch core (core_*_test.cpp): floors, streams
// and the invariants every run must satisfy.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "engine/io/movingai_map.h"
#include "engine/map/chu2024_floor.h"
#include "engine/routing/route_table.h"
#include "engine/sim/fleet_placement.h"
#include "engine/sim/stream_result.h"
#include "engine/sim/random_orders.h"

namespace dispatch::engine::testing {

struct World {
  std::shared_ptr<const WarehouseMap> map;
  std::shared_ptr<const RouteTable> routes;
};

// A floor and its route table.
inline World WorldOf(Result<WarehouseMap> m) {
  if (!m.ok()) throw std::runtime_error(m.error().message);
  World x;
  x.map = std::make_shared<const WarehouseMap>(std::move(m).value());
  auto t = MakeRouteTable(x.map, {});
  if (!t.ok()) throw std::runtime_error(t.error().message);
  x.routes = std::move(t).value();
  return x;
}

inline World Chu() {
  static const World w = WorldOf(BuildChu2024Floor());
  return w;
}

inline World GridWorld(const std::string& rows) {
  const std::size_t width = rows.find('\n');
  const std::size_t height = static_cast<std::size_t>(std::count(rows.begin(), rows.end(), '\n'));
  return WorldOf(ParseMovingAiMap("type octile\nheight " + std::to_string(height) + "\nwidth " +
                                      std::to_string(width) + "\nmap\n" + rows,
                                  "grid"));
}

// Invariants every run must satisfy, whatever the numbers.
inline void ExpectSane(const World& w, const std::vector<Order>& orders, const StreamResult& r,
                const StreamConfig& c) {
  ASSERT_EQ(r.orders.size(), orders.size());
  double total_direct = 0, last_release = 0;
  for (std::size_t i = 0; i < orders.size(); ++i) {
    const Order& o = orders[i];
    const StreamOrderOutcome& out = r.orders[i];
    EXPECT_EQ(out.order_id, o.id);
    const double direct = w.routes->Cost(o.picks.front(), o.drop);
    // A task table's row without a release time is released on acceptance (its created time).
    const double release = o.release_time.value_or(o.created_time);
    if (out.completed) {
      // Released, driven from the pick to the drop at most at speed v, worked twice.
      EXPECT_GE(out.completion_time + 1e-6, release + direct + 2 * o.work_time) << o.id;
      EXPECT_LE(out.completion_time, r.makespan + 1e-9);
      EXPECT_FALSE(out.robot.empty());
      total_direct += direct * c.allocation.speed;
      last_release = std::max(last_release, release);
    } else {
      EXPECT_FALSE(out.failure.empty()) << o.id;
    }
  }
  EXPECT_GE(r.total_distance + 1e-6, total_direct);
  if (r.completed > 0) {
    EXPECT_GE(r.makespan, last_release);
    EXPECT_NEAR(r.throughput_per_hour, static_cast<double>(r.completed) / r.makespan * 3600, 1e-6);
    EXPECT_GT(r.mean_completion, 0.0);
  }
  EXPECT_LT(r.end_time, c.max_time);  // nothing hit the time limit ("waits forever")
}

// 18 robots at the Chu2024 floor's stations and `count` random orders (RandomOrders, `seed`,
// a `formation_share` of them formation orders).
struct Stream {
  std::vector<FleetRobot> robots;
  std::vector<Order> orders;
};
inline Stream ChuStream(const World& w, std::size_t count, std::uint64_t seed,
                        double formation_share = 0.0) {
  auto robots = PlaceRobots(*w.map, 18);
  if (!robots.ok()) throw std::runtime_error(robots.error().message);
  RandomOrderOptions ro;
  ro.count = count;
  ro.seed = seed;
  ro.formation_share = formation_share;
  auto orders = RandomOrders(*w.map, ro);
  if (!orders.ok()) throw std::runtime_error(orders.error().message);
  return {std::move(robots).value(), std::move(orders).value()};
}

// Small dense grids: every lane a bidirectional single lane, picks and drops inside one-cell
// aisles (the liveness tests).
inline const std::vector<std::string>& DenseGrids() {
  static const std::vector<std::string> maps = {
      "S...S...SE\n"
      ".@@.@@.@@.\n"
      ".@@.@@.@@.\n"
      "E........E\n"
      ".@@.@@.@@.\n"
      ".@@.@@.@@.\n"
      "S...S...SE\n"
      "..........\n",
      "S..S..S..S..\n"
      "............\n"
      "..@@..@@..@.\n"
      "E.@@..@@..@E\n"
      "............\n"
      "............\n"
      "..@@..@@..@.\n"
      "E.@@..@@..@E\n"
      "............\n"
      "S..S..S..S..\n"};
  return maps;
}

}  // namespace dispatch::engine::testing
