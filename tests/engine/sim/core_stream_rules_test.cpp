// SimulateOnCore's own safety check and its inputs' rules: without intersection grants robots
// cross each other inside intersections and the run's CheckSafety says so (the check can
// fail); a task table's release times hold.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "engine/cli/scenario.h"
#include "engine/sim/core_stream.h"
#include "tests/engine/sim/stream_test_support.h"

namespace dispatch::engine::testing {
namespace {

TEST(CoreStreamRulesTest, SelfCheckCatchesCrossingsWithoutIntersectionGrants) {
  const World w = Chu();
  const Stream st = ChuStream(w, 100, 7);
  StreamConfig c;
  c.max_time = 5000;
  c.check_safety = true;
  c.traffic.intersection_grants = false;
  auto r = SimulateOnCore(w.map, w.routes, st.robots, st.orders, c);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_TRUE(r->safety.has_value());
  std::size_t crossings = 0;
  for (const SafetyViolation& v : r->safety->violations) crossings += v.kind == ViolationKind::kCrossing;
  EXPECT_GT(crossings, 0u);
  EXPECT_EQ(r->traffic.grants, 0u);
}

TEST(CoreStreamRulesTest, TaskTableReleaseTimesAreRespected) {
  const World w = Chu();
  const auto path = std::filesystem::path(DISPATCH_BINARY_DIR) / "core_stream_release.csv";
  {
    std::ofstream out(path);
    out << "task,formation,picks,drop,release\n"
        << "1,0,19 17,6.5 2.75,0\n"
        << "2,0,19 17,6.5 2.75,100\n"
        << "3,0,20.5 10.5,6.5 2.75,\n";
  }
  auto orders = LoadTaskTableOrders(*w.map, path.string());
  ASSERT_TRUE(orders.ok()) << orders.error().message;
  ASSERT_EQ(orders->size(), 3u);
  const Order t2 = orders->at(1);
  auto robots = PlaceRobots(*w.map, 4);
  ASSERT_TRUE(robots.ok());
  StreamConfig c;
  auto r = SimulateOnCore(w.map, w.routes, *robots, *orders, c);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_TRUE(r->all_completed());
  // The outcomes in release order: T1 (0 s), T3 (no release value: released on acceptance,
  // created_time = its row index 2), T2 (100 s).
  ASSERT_EQ(r->orders.size(), 3u);
  EXPECT_EQ(r->orders[1].order_id, "T3");
  EXPECT_DOUBLE_EQ(r->orders[1].release_time, 2.0);
  EXPECT_EQ(r->orders[2].order_id, "T2");
  EXPECT_DOUBLE_EQ(r->orders[2].release_time, 100.0);
  // T2 picks where T1 picked: it cannot finish before its release plus pick -> drop.
  EXPECT_GE(r->orders[2].completion_time, 100.0 + w.routes->Cost(t2.picks[0], t2.drop) + 2 * t2.work_time);
}

}  // namespace
}  // namespace dispatch::engine::testing
