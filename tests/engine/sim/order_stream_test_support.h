// Helpers of the order-stream tests (order_stream_test.cpp, order_stream_formation_test.cpp):
// floors, streams and the invariants every run must satisfy.
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
#include "engine/sim/order_stream.h"
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
    if (out.completed) {
      // Released, driven from the pick to the drop at most at speed v, worked twice.
      EXPECT_GE(out.completion_time + 1e-6, *o.release_time + direct + 2 * o.work_time) << o.id;
      EXPECT_LE(out.completion_time, r.makespan + 1e-9);
      EXPECT_FALSE(out.robot.empty());
      total_direct += direct * c.allocation.speed;
      last_release = std::max(last_release, *o.release_time);
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
  EXPECT_EQ(r.times.size(), r.min_distance.size());
}

// The run's own CheckSafety (StreamConfig::check_safety): eps1 between every pair of robots
// and no crossing movements inside one intersection at a time.
inline void ExpectSafe(const StreamResult& r) {
  ASSERT_TRUE(r.safety.has_value());
  EXPECT_TRUE(r.safety->ok()) << r.safety->violations.size() << " violations, first: "
                              << r.safety->violations.front().Describe();
  // The series measures pairs within distance_cap only (+inf when none was that close).
  if (std::isfinite(r.overall_min_distance)) {
    EXPECT_NEAR(r.safety->min_robot_distance, r.overall_min_distance, 1e-9);
  }
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

// Failures a run may report: blocked with no alternative, as the controller or a formation's
// rendezvous says.
inline void ExpectStatedFailures(const StreamResult& r) {
  for (const StreamOrderOutcome& o : r.orders) {
    if (!o.completed) {
      EXPECT_EQ(o.failure.rfind("blocked: ", 0), 0u) << o.order_id << ": " << o.failure;
    }
  }
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

// Liveness on DenseGrids(): 4, 6 and 8 robots, seeds 1..5, 40 random orders each (a
// `formation_share` of them formation orders). Every run is safe (eps1, no crossings),
// sane, nothing runs into the time limit, and every order that fails says it was blocked.
// Returns (completed, total) over all runs.
inline std::pair<std::size_t, std::size_t> DenseGridLiveness(double formation_share) {
  std::size_t total = 0, completed = 0;
  for (const std::string& rows : DenseGrids()) {
    const World w = GridWorld(rows);
    for (std::size_t n : {4u, 6u, 8u}) {
      for (std::uint64_t seed = 1; seed <= 5; ++seed) {
        SCOPED_TRACE("robots " + std::to_string(n) + " seed " + std::to_string(seed));
        auto robots = PlaceRobots(*w.map, n);
        EXPECT_TRUE(robots.ok());
        RandomOrderOptions ro;
        ro.count = 40;
        ro.seed = seed;
        ro.interval = 2.0;
        ro.formation_share = formation_share;
        auto orders = RandomOrders(*w.map, ro);
        EXPECT_TRUE(orders.ok());
        if (!robots.ok() || !orders.ok()) continue;
        StreamConfig c;
        c.max_time = 2000;
        c.record_series = false;
        c.check_safety = true;
        auto r = SimulateOrderStream(w.map, w.routes, *robots, *orders, c);
        EXPECT_TRUE(r.ok()) << r.error().message;
        if (!r.ok()) continue;
        ExpectSafe(*r);
        ExpectSane(w, *orders, *r, c);
        ExpectStatedFailures(*r);
        EXPECT_GE(r->overall_min_distance, 0.6 - 1e-9);  // point clearance (eps1)
        total += r->orders.size();
        completed += r->completed;
      }
    }
  }
  return {completed, total};
}

}  // namespace dispatch::engine::testing
