// Order-stream simulation under the online traffic controller: the strategy
// comparison on the Chu2024 floor, release times and seeded liveness on small dense grids
// where every lane is a bidirectional single lane. (The Wang2019 head-on scenario runs on the
// dispatch core: head_on_scenario_test.cpp.)
#include "engine/sim/order_stream.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <string>

#include "engine/cli/scenario.h"
#include "tests/engine/sim/order_stream_test_support.h"

namespace dispatch::engine::testing {
namespace {

TEST(OrderStreamTest, StrategiesOnTwoHundredRandomOrdersOnChu2024) {
  const World w = Chu();
  const Stream st = ChuStream(w, 200, 7);
  std::vector<StreamResult> results;
  for (auto [strategy, zeta] : {std::pair{AllocationStrategy::kAuction, 100.0},
                                std::pair{AllocationStrategy::kAuction, 0.0},
                                std::pair{AllocationStrategy::kGreedy, 0.0}}) {
    StreamConfig c;
    c.strategy = strategy;
    c.allocation.zeta = zeta;
    c.max_time = 5000;
    c.check_safety = true;
    auto r = SimulateOrderStream(w.map, w.routes, st.robots, st.orders, c);
    ASSERT_TRUE(r.ok()) << r.error().message;
    ExpectSafe(*r);
    EXPECT_TRUE(r->all_completed()) << AllocationStrategyName(strategy) << " " << zeta;
    EXPECT_TRUE(r->blocked.empty());
    ExpectSane(w, st.orders, *r, c);
    // Point clearance (eps1) holds on the Chu2024 floor: no two robots closer than 0.6 m.
    EXPECT_GE(r->overall_min_distance, 0.6 - 1e-9);
    EXPECT_GT(r->traffic.grants, 0u);  // the floor's intersections were used
    results.push_back(std::move(r).value());
  }
  // The auction spreads work over the fleet: every robot serves some order.
  std::set<std::string> used;
  for (const auto& o : results[0].orders) used.insert(o.robot);
  EXPECT_EQ(used.size(), 18u);
}

TEST(OrderStreamTest, SelfCheckCatchesCrossingsWithoutIntersectionGrants) {
  // The same kind of stream with the controller's intersection grants off: robots still keep
  // point clearance but enter an intersection whatever crosses it, and the run's CheckSafety
  // says so (the check above can fail).
  const World w = Chu();
  const Stream st = ChuStream(w, 100, 7);
  StreamConfig c;
  c.max_time = 5000;
  c.check_safety = true;
  c.traffic.intersection_grants = false;
  auto r = SimulateOrderStream(w.map, w.routes, st.robots, st.orders, c);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_TRUE(r->safety.has_value());
  std::size_t crossings = 0;
  for (const SafetyViolation& v : r->safety->violations) crossings += v.kind == ViolationKind::kCrossing;
  EXPECT_GT(crossings, 0u);
}

TEST(OrderStreamTest, IsDeterministic) {
  const World w = Chu();
  const Stream st = ChuStream(w, 40, 3);
  StreamConfig c;
  c.check_safety = false;
  auto a = SimulateOrderStream(w.map, w.routes, st.robots, st.orders, c);
  auto b = SimulateOrderStream(w.map, w.routes, st.robots, st.orders, c);
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(a->orders.size(), b->orders.size());
  for (std::size_t i = 0; i < a->orders.size(); ++i) {
    EXPECT_EQ(a->orders[i].robot, b->orders[i].robot);
    EXPECT_EQ(a->orders[i].completion_time, b->orders[i].completion_time);
  }
  EXPECT_EQ(a->min_distance, b->min_distance);
  EXPECT_FALSE(a->safety.has_value());  // not asked for
}

TEST(OrderStreamTest, TaskTableReleaseTimesAreRespected) {
  const World w = Chu();
  const auto path = std::filesystem::path(DISPATCH_BINARY_DIR) / "order_stream_release.csv";
  {
    std::ofstream out(path);
    out << "task,formation,picks,drop,release\n"
        << "1,0,19 17,6.5 2.75,0\n"
        << "2,0,19 17,6.5 2.75,100\n"
        << "3,0,20.5 10.5,6.5 2.75,\n";
  }
  auto orders = LoadTaskTableOrders(*w.map, path.string());
  ASSERT_TRUE(orders.ok()) << orders.error().message;
  auto robots = PlaceRobots(*w.map, 4);
  StreamConfig c;
  auto r = SimulateOrderStream(w.map, w.routes, *robots, *orders, c);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_TRUE(r->all_completed());
  EXPECT_DOUBLE_EQ(r->orders[1].release_time, 100.0);
  // T2 picks where T1 picked: it cannot finish before its release plus pick -> drop.
  EXPECT_GE(r->orders[1].completion_time,
            100.0 + w.routes->Cost(orders->at(1).picks[0], orders->at(1).drop));
  // No release column value: released on acceptance (created_time = row index 2).
  EXPECT_DOUBLE_EQ(r->orders[2].release_time, 2.0);
}

TEST(OrderStreamTest, RejectsBadConfigAndFormationsWithoutThreeRobots) {
  const World w = Chu();
  auto orders = LoadTaskTableOrders(
      *w.map, std::string(DISPATCH_SHARED_DIR) + "/scenarios/chu2024-table1.csv");
  ASSERT_TRUE(orders.ok());
  auto two = PlaceRobots(*w.map, 2);
  auto r = SimulateOrderStream(w.map, w.routes, *two, *orders, {});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("formation order T1 needs 3 robots"), std::string::npos)
      << r.error().message;
  auto robots = PlaceRobots(*w.map, 18);
  StreamConfig bad;
  bad.time_step = 0;
  EXPECT_FALSE(SimulateOrderStream(w.map, w.routes, *robots, {}, bad).ok());
  EXPECT_FALSE(SimulateOrderStream(w.map, w.routes, {}, {}, {}).ok());
}

// Liveness: seeded random streams on small dense grids (every lane a bidirectional single
// lane, picks and drops inside one-cell aisles). Every order completes, or fails with a
// stated reason; nothing waits until the time limit.
TEST(OrderStreamTest, LivenessOnSmallDenseGrids) {
  const auto [completed, total] = DenseGridLiveness(0.0);
  std::printf("liveness: %zu/%zu orders completed\n", completed, total);
  EXPECT_GE(static_cast<double>(completed), 0.95 * static_cast<double>(total));
}

}  // namespace
}  // namespace dispatch::engine::testing
