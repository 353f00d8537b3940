// Offline simulator (SPEC §3.8) under the Chu2024 §3.3 traffic rules, and the seed's Fig. 8.
#include "engine/sim/simulator.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "engine/allocation/auction_allocator.h"
#include "engine/cli/scenario.h"
#include "engine/map/chu2024_floor.h"
#include "engine/map/map_builder.h"
#include "engine/routing/route_table.h"
#include "engine/traffic/safety_check.h"

namespace dispatch::engine {
namespace {

std::shared_ptr<const RouteTable> Routes(std::shared_ptr<const WarehouseMap> map) {
  auto t = MakeRouteTable(std::move(map), {});
  if (!t.ok()) throw std::runtime_error(t.error().message);
  return std::shared_ptr<const RouteTable>(std::move(t).value());
}

// A one-way cross: W -> E along y = 5 and S -> N along x = 5, meeting in intersection X
// (inner point C) with approach points 0.6 m before it; a lane continues past E to F.
std::shared_ptr<const WarehouseMap> CrossMap() {
  MapBuilder b("cross");
  b.SetFloor({-1, -1}, {14, 11});
  b.AddRectZone("z", {-1, -1}, {14, 11});
  b.AddPoint("W", {0, 5}, PointKind::kPark);
  b.AddPoint("a1", {3, 5}, PointKind::kLane);
  b.AddPoint("A", {4.4, 5}, PointKind::kLane);
  b.AddPoint("C", {5, 5}, PointKind::kIntersection);
  b.AddPoint("e1", {7, 5}, PointKind::kPick);
  b.AddPoint("E", {10, 5}, PointKind::kDrop);
  b.AddPoint("F", {13, 5}, PointKind::kDrop);
  b.AddPoint("S", {5, 0}, PointKind::kPark);
  b.AddPoint("B", {5, 4.4}, PointKind::kLane);
  b.AddPoint("n1", {5, 7}, PointKind::kPick);
  b.AddPoint("N", {5, 10}, PointKind::kDrop);
  for (auto [f, t] : std::vector<std::pair<const char*, const char*>>{
           {"W", "a1"}, {"a1", "A"}, {"A", "C"}, {"C", "e1"}, {"e1", "E"}, {"E", "F"},
           {"S", "B"}, {"B", "C"}, {"C", "n1"}, {"n1", "N"}}) {
    b.AddPath(f, t);
  }
  b.AddIntersection("X", {"C"}, {"A", "B"});
  MapBuildOptions options;
  options.check_service_connectivity = false;
  auto map = b.Build(options);
  if (!map.ok()) throw std::runtime_error(map.error().message);
  return std::make_shared<const WarehouseMap>(std::move(map).value());
}

class CrossTest : public ::testing::Test {
 protected:
  void SetUp() override {
    map_ = CrossMap();
    routes_ = Routes(map_);
  }
  PointId P(const std::string& name) const { return *map_->FindPoint(name); }
  FleetState Fleet(const std::vector<std::pair<std::string, std::string>>& robots) const {
    std::vector<FleetRobot> fleet;
    for (const auto& [id, at] : robots) fleet.push_back({id, P(at), 0.0});
    auto s = FleetState::Create(map_, routes_, fleet);
    if (!s.ok()) throw std::runtime_error(s.error().message);
    return std::move(s).value();
  }
  void Assign(FleetState& s, std::size_t robot, const std::string& order, const std::string& pick,
              const std::string& drop) const {
    ASSERT_TRUE(s.AssignSingle(robot, order, s.TaskOf({P(pick)}, P(drop), 5.0)).ok());
  }
  std::shared_ptr<const WarehouseMap> map_;
  std::shared_ptr<const RouteTable> routes_;
};

TEST_F(CrossTest, SingleRobotCompletesAtItsPlannedEtaWhenAlone) {
  FleetState s = Fleet({{"R1", "W"}});
  Assign(s, 0, "T1", "e1", "E");
  auto r = Simulate(s);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_EQ(r->orders.size(), 1u);
  const OrderOutcome& o = r->orders[0];
  ASSERT_TRUE(o.completed) << o.failure;
  EXPECT_NEAR(o.planned_time, s.plan(0).end_time(), 1e-9);
  EXPECT_NEAR(o.completion_time, o.planned_time, 1e-6);  // 7 m + 5 s + 3 m + 5 s at 1 m/s
  EXPECT_NEAR(o.completion_time, 20.0, 1e-6);
  EXPECT_NEAR(r->total_distance, 10.0, 1e-6);
  EXPECT_EQ(r->total_waiting_time, 0.0);
  EXPECT_EQ(r->grants_issued, 1u);
  EXPECT_NEAR(r->makespan, 20.0, 1e-6);
  EXPECT_EQ(r->times.size(), r->min_distance.size());
}

TEST_F(CrossTest, TwoRobotsCrossingWithRulesOnAreSafeAndOneWaits) {
  FleetState s = Fleet({{"R1", "W"}, {"R2", "S"}});
  Assign(s, 0, "T1", "e1", "E");
  Assign(s, 1, "T2", "n1", "N");
  const TrafficConfig traffic;
  // Their plans meet in C at t = 5 s.
  EXPECT_LT((s.plan(0).PositionAt(5.0) - s.plan(1).PositionAt(5.0)).norm(), 1e-9);
  SimConfig off;
  off.traffic.rules_enabled = false;
  off.check_safety = true;  // the run's own check (default in debug builds only)
  off.record_frames = false;
  auto without = Simulate(s, off);
  ASSERT_TRUE(without.ok());
  EXPECT_LT(without->overall_min_distance, traffic.epsilon_single_single);
  ASSERT_TRUE(without->safety.has_value());
  EXPECT_FALSE(without->safety->ok());
  EXPECT_TRUE(without->frames.empty());  // checked, then not kept

  SimConfig on;
  on.check_safety = true;
  auto with = Simulate(s, on);
  ASSERT_TRUE(with.ok()) << with.error().message;
  ASSERT_TRUE(with->all_completed());
  const SafetyReport safety = CheckSafety(with->frames, *map_, traffic);
  EXPECT_TRUE(safety.ok()) << safety.violations.front().Describe();
  ASSERT_TRUE(with->safety.has_value());
  EXPECT_EQ(with->safety->violations.size(), safety.violations.size());
  EXPECT_EQ(with->safety->min_robot_distance, safety.min_robot_distance);
  EXPECT_GE(with->overall_min_distance, traffic.epsilon_single_single - 1e-9);
  EXPECT_GT(with->total_waiting_time, 0.0);
  EXPECT_GE(with->stops, 1);
  EXPECT_EQ(with->grants_issued, 2u);
  EXPECT_EQ(with->intersection_grants, 2u);
  // Exactly one of them was delayed (R1 asks first at equal times: "R1" < "R2").
  EXPECT_NEAR(with->orders[0].completion_time, 20.0, 1e-6);
  EXPECT_GT(with->orders[1].completion_time, 20.0 + 0.5);
}

TEST_F(CrossTest, RearEndRuleKeepsTheFollowerBehind) {
  // R2 starts 3 m behind R1 on the same lane; R1 stops at e1 to pick, R2 must wait behind.
  FleetState s = Fleet({{"R1", "a1"}, {"R2", "W"}});
  Assign(s, 0, "T1", "e1", "E");
  Assign(s, 1, "T2", "e1", "F");
  auto r = Simulate(s);
  ASSERT_TRUE(r.ok());
  ASSERT_TRUE(r->all_completed());
  EXPECT_GE(r->overall_min_distance, 0.6 - 1e-9);
  EXPECT_TRUE(CheckSafety(r->frames, *map_, TrafficConfig{}).ok());
  EXPECT_GT(r->total_waiting_time, 0.0);
}

TEST_F(CrossTest, ARobotThatCannotPassIsReportedBlocked) {
  // R1 ends its plan at E and stays there (robots do not leave the floor): R2, whose route
  // runs through E, waits behind it until the bound and its order fails with a reason.
  FleetState s = Fleet({{"R1", "a1"}, {"R2", "W"}});
  Assign(s, 0, "T1", "e1", "E");
  Assign(s, 1, "T2", "e1", "F");
  SimConfig config;
  config.finished_robots_leave_floor = false;
  config.max_wait = 10.0;
  auto r = Simulate(s, config);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r->orders[0].completed);
  EXPECT_FALSE(r->orders[1].completed);
  EXPECT_NE(r->orders[1].failure.find("blocked: R2"), std::string::npos) << r->orders[1].failure;
  ASSERT_EQ(r->blocked.size(), 1u);
  EXPECT_LT(r->end_time, 60.0);
}

TEST_F(CrossTest, RejectsAQueueThatDoesNotMatchThePlan) {
  FleetState s = Fleet({{"R1", "W"}});
  Assign(s, 0, "T1", "e1", "E");
  std::vector<SimRobot> robots{{"R1", s.plan(0), {}}};
  EXPECT_EQ(Simulate(*map_, robots).error().code, ErrorCode::kInvalidArgument);
  SimConfig bad;
  bad.time_step = 0;
  EXPECT_FALSE(Simulate(s, bad).ok());
}

// Seed 000 §4.2, Fig. 8: Table 1 on the Chu2024 floor, rules off vs on.
class Fig8Test : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto m = BuildChu2024Floor();
    ASSERT_TRUE(m.ok()) << m.error().message;
    map_ = new std::shared_ptr<const WarehouseMap>(
        std::make_shared<const WarehouseMap>(std::move(m).value()));
    auto orders = LoadTaskTableOrders(**map_, std::string(DISPATCH_SHARED_DIR) +
                                                  "/scenarios/chu2024-table1.csv");
    ASSERT_TRUE(orders.ok()) << orders.error().message;
    auto robots = RobotsAtStations(**map_);
    ASSERT_TRUE(robots.ok());
    auto state = FleetState::Create(*map_, Routes(*map_), *robots);
    ASSERT_TRUE(state.ok());
    state_ = new FleetState(std::move(state).value());
    AuctionAllocator auction;
    for (const auto& a : AllocateAll(auction, *orders, *state_)) {
      ASSERT_TRUE(a.award.ok()) << a.order_id;
    }
  }
  static void TearDownTestSuite() {
    delete state_;
    delete map_;
  }
  static std::shared_ptr<const WarehouseMap>* map_;
  static FleetState* state_;
};
std::shared_ptr<const WarehouseMap>* Fig8Test::map_ = nullptr;
FleetState* Fig8Test::state_ = nullptr;

TEST_F(Fig8Test, RulesOnEveryOrderCompletesSafely) {
  auto r = Simulate(*state_);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_EQ(r->orders.size(), 6u);
  for (const OrderOutcome& o : r->orders) {
    EXPECT_TRUE(o.completed) << o.order_id << ": " << o.failure;
    EXPECT_GE(o.completion_time, o.planned_time - 1e-6) << o.order_id;
  }
  const TrafficConfig traffic;
  const SafetyReport safety = CheckSafety(r->frames, **map_, traffic);
  EXPECT_TRUE(safety.ok()) << safety.violations.size() << " violations, first "
                           << safety.violations.front().Describe();
  EXPECT_GE(r->overall_min_distance, traffic.epsilon_single_single);  // paper: > 0.6 m
  EXPECT_GT(r->grants_issued, 0u);
  EXPECT_TRUE(r->blocked.empty());
}

TEST_F(Fig8Test, RulesOffRobotsComeCloserThanEps1) {
  SimConfig off;
  off.traffic.rules_enabled = false;
  auto r = Simulate(*state_, off);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_TRUE(r->all_completed());
  EXPECT_LT(r->overall_min_distance, 0.5);  // paper: < 0.5 m without rules
  EXPECT_FALSE(CheckSafety(r->frames, **map_, off.traffic).ok());
  EXPECT_EQ(r->grants_issued, 0u);
  EXPECT_EQ(r->total_waiting_time, 0.0);
}

TEST_F(Fig8Test, IsDeterministic) {
  auto a = Simulate(*state_);
  auto b = Simulate(*state_);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->min_distance, b->min_distance);
  EXPECT_EQ(a->makespan, b->makespan);
}

// Few robots, so each serves several tasks: formation parts are followed by single tasks
// and other formations (members split up and regroup).
TEST(SimulatorMultiTaskTest, Table1WithFiveRobotsCompletesSafely) {
  auto m = BuildChu2024Floor();
  ASSERT_TRUE(m.ok());
  auto map = std::make_shared<const WarehouseMap>(std::move(m).value());
  auto orders = LoadTaskTableOrders(*map, std::string(DISPATCH_SHARED_DIR) +
                                              "/scenarios/chu2024-table1.csv");
  ASSERT_TRUE(orders.ok());
  auto robots = RobotsAtStations(*map, 5);
  ASSERT_TRUE(robots.ok());
  auto state = FleetState::Create(map, Routes(map), *robots);
  ASSERT_TRUE(state.ok());
  AuctionAllocator auction;
  for (const auto& a : AllocateAll(auction, *orders, state.value())) ASSERT_TRUE(a.award.ok());
  std::size_t most = 0;
  for (std::size_t r = 0; r < state->robot_count(); ++r) {
    most = std::max(most, state->queue(r).size());
  }
  ASSERT_GE(most, 3u);
  for (bool rules : {false, true}) {
    SimConfig config;
    config.traffic.rules_enabled = rules;
    auto r = Simulate(*state, config);
    ASSERT_TRUE(r.ok()) << r.error().message;
    for (const OrderOutcome& o : r->orders) {
      EXPECT_TRUE(o.completed) << o.order_id << ": " << o.failure;
      EXPECT_GE(o.completion_time, o.planned_time - 1e-6) << o.order_id;
      if (!rules) {
        EXPECT_NEAR(o.completion_time, o.planned_time, 0.5) << o.order_id;
      }
    }
    if (rules) {
      const SafetyReport safety = CheckSafety(r->frames, *map, config.traffic);
      EXPECT_TRUE(safety.ok()) << safety.violations.front().Describe();
    }
  }
}

}  // namespace
}  // namespace dispatch::engine
