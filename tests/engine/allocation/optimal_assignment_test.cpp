#include "engine/allocation/optimal_assignment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "allocation_test_util.h"
#include "engine/allocation/auction_allocator.h"

namespace dispatch::engine {
namespace {

using testing_util::Grid;
using testing_util::MakeFleet;
using testing_util::MakeOrder;
using testing_util::Pt;
using testing_util::Routes;

// Independent model of the batch cost: each robot's final queue timed by BuildPlan; with no
// waiting, T_t = plan duration, T_w = sum n_c t_w plus the drops' work, T_d = T_t - T_w
// (Chu2024 eqs. (1)-(3); n_c counts the picks).
double ModelCost(const FleetState& s, const std::vector<Order>& orders,
                 const std::vector<std::size_t>& map, const AllocationConfig& c) {
  double total = 0.0;
  for (std::size_t r = 0; r < s.robot_count(); ++r) {
    std::vector<PlanTask> tasks;
    double work = 0.0;
    for (std::size_t k = 0; k < orders.size(); ++k) {
      if (map[k] != r) continue;
      const double drop = c.drop_time.value_or(orders[k].work_time);
      tasks.push_back({orders[k].picks, orders[k].drop, orders[k].work_time, drop});
      work += orders[k].picks.size() * orders[k].work_time + drop;
    }
    Result<Plan> plan = BuildPlan(s.map(), s.routes(), s.robot(r).start, 0.0, c.speed, tasks);
    if (!plan.ok()) return INFINITY;
    const double t_t = plan->end_time();
    total += c.alpha * t_t + c.beta * (t_t - work);
  }
  return total;
}

TEST(OptimalAssignmentTest, RandomTinyInstances) {
  auto map = Grid(5, 5, 1.0, 5, {{0, 4}, {4, 4}, {2, 2}, {4, 0}}, {{0, 0}, {2, 4}});
  auto routes = Routes(map);
  const std::vector<PointId> picks = {Pt(*map, "0,4"), Pt(*map, "4,4"), Pt(*map, "2,2"),
                                      Pt(*map, "4,0")};
  const std::vector<PointId> drops = {Pt(*map, "0,0"), Pt(*map, "2,4")};
  int hungarian_checked = 0, auction_above = 0;
  for (int seed = 0; seed < 60; ++seed) {
    std::mt19937 rng(seed);
    const int m = 2 + static_cast<int>(rng() % 3);
    const int n = 2 + static_cast<int>(rng() % 3);
    AllocationConfig c;
    c.zeta = 0.0;
    c.alpha = 0.5;
    c.beta = 0.5;
    // Work at the drop: the order's t_w (default), the seed's none, or its own.
    if (seed % 3 != 0) c.drop_time = seed % 3 == 1 ? 0.0 : 1.5;
    std::vector<FleetRobot> robots;
    for (int i = 0; i < m; ++i) {
      robots.push_back({"R" + std::to_string(i), static_cast<PointId>(rng() % map->point_count()), 0.0});
    }
    std::vector<Order> orders;
    for (int k = 0; k < n; ++k) {
      std::vector<PointId> p = {picks[rng() % picks.size()]};
      if (rng() % 3 == 0) p.push_back(picks[rng() % picks.size()]);
      Order o = MakeOrder("o" + std::to_string(k), p, drops[rng() % drops.size()], false, k);
      o.work_time = 1.0 + static_cast<double>(rng() % 4);
      orders.push_back(o);
    }
    FleetState s = MakeFleet(map, routes, robots, c);
    Result<BatchAssignment> brute = BruteForceAssignment(s, orders);
    ASSERT_TRUE(brute.ok()) << brute.error().message;
    // Independent enumeration of every map with the BuildPlan model.
    double best = INFINITY;
    std::vector<std::size_t> map_k(static_cast<std::size_t>(n), 0);
    for (int code = 0; code < static_cast<int>(std::pow(m, n)); ++code) {
      int x = code;
      for (int k = n - 1; k >= 0; --k) {
        map_k[static_cast<std::size_t>(k)] = static_cast<std::size_t>(x % m);
        x /= m;
      }
      best = std::min(best, ModelCost(s, orders, map_k, c));
    }
    EXPECT_NEAR(brute->cost, best, 1e-6) << "seed " << seed;
    EXPECT_NEAR(ModelCost(s, orders, brute->robot_of_order, c), brute->cost, 1e-6);
    Result<double> again = BatchCost(s, orders, brute->robot_of_order);
    ASSERT_TRUE(again.ok());
    EXPECT_DOUBLE_EQ(*again, brute->cost);

    if (n <= m) {
      OptimalAssignmentOptions one;
      one.one_order_per_robot = true;
      Result<BatchAssignment> b1 = BruteForceAssignment(s, orders, one);
      Result<BatchAssignment> h = HungarianAssignment(s, orders);
      ASSERT_TRUE(b1.ok() && h.ok());
      EXPECT_NEAR(h->cost, b1->cost, 1e-6) << "seed " << seed;
      EXPECT_GE(h->cost, brute->cost - 1e-9);
      std::vector<bool> used(static_cast<std::size_t>(m), false);
      for (std::size_t r : h->robot_of_order) {
        EXPECT_FALSE(used[r]);
        used[r] = true;
      }
      ++hungarian_checked;
    } else {
      EXPECT_FALSE(HungarianAssignment(s, orders).ok());
    }

    // The auction (zeta = 0) on a fresh fleet: its total is never below the optimum.
    FleetState fresh = MakeFleet(map, routes, robots, c);
    AuctionAllocator auction;
    const std::vector<OrderAllocation> out = AllocateAll(auction, orders, fresh);
    std::vector<std::size_t> auction_map;
    for (const OrderAllocation& a : out) {
      ASSERT_TRUE(a.award.ok());
      auction_map.push_back(*fresh.FindRobot(a.award->winners[0]));
    }
    double total = 0.0;
    for (std::size_t r = 0; r < fresh.robot_count(); ++r) {
      const QueueSummary& q = fresh.summary(r);
      total += c.alpha * (q.travel_time + q.work_time) + c.beta * q.travel_time;
    }
    Result<double> auction_cost = BatchCost(s, orders, auction_map);
    ASSERT_TRUE(auction_cost.ok());
    EXPECT_NEAR(total, *auction_cost, 1e-9);
    EXPECT_GE(total, brute->cost - 1e-9) << "seed " << seed;
    if (total > brute->cost + 1e-9) ++auction_above;
  }
  EXPECT_GT(hungarian_checked, 10);
  std::cout << "auction above the optimum on " << auction_above << " of 60 instances\n";
}

TEST(OptimalAssignmentTest, RejectsFormationsAndHugeBatches) {
  auto map = Grid(3, 1, 1.0, 3, {{1, 0}}, {{2, 0}});
  auto routes = Routes(map);
  FleetState s = MakeFleet(map, routes, {{"R0", 0, 0.0}, {"R1", 0, 0.0}, {"R2", 0, 0.0}});
  const Order f = MakeOrder("f", {Pt(*map, "1,0")}, Pt(*map, "2,0"), true);
  Result<BatchAssignment> r = BruteForceAssignment(s, {f});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("order f"), std::string::npos);
  std::vector<Order> many(20, MakeOrder("o", {Pt(*map, "1,0")}, Pt(*map, "2,0")));
  Result<BatchAssignment> big = BruteForceAssignment(s, many);
  ASSERT_FALSE(big.ok());
  EXPECT_EQ(big.error().code, ErrorCode::kFailedPrecondition);
}

TEST(OptimalAssignmentTest, ARobotSubsetQueueRoomAndAStopBoundTheSearch) {
  auto map = Grid(5, 1, 1.0, 5, {{1, 0}, {3, 0}}, {{4, 0}});
  auto routes = Routes(map);
  AllocationConfig c;
  c.max_queue = 2;
  FleetState s = MakeFleet(map, routes, {{"R0", Pt(*map, "1,0"), 0.0}, {"R1", Pt(*map, "3,0"), 0.0},
                                         {"R2", Pt(*map, "0,0"), 0.0}}, c);
  const std::vector<Order> orders = {MakeOrder("a", {Pt(*map, "1,0")}, Pt(*map, "4,0")),
                                     MakeOrder("b", {Pt(*map, "3,0")}, Pt(*map, "4,0")),
                                     MakeOrder("c", {Pt(*map, "3,0")}, Pt(*map, "4,0"))};
  OptimalAssignmentOptions only;
  only.robots = {0, 2};  // not R1, which stands at b's and c's pick
  Result<BatchAssignment> sub = BruteForceAssignment(s, orders, only);
  ASSERT_TRUE(sub.ok()) << sub.error().message;
  for (std::size_t r : sub->robot_of_order) EXPECT_NE(r, 1u);
  Result<double> full = BatchCost(s, orders, sub->robot_of_order);
  ASSERT_TRUE(full.ok());
  EXPECT_DOUBLE_EQ(sub->cost, *full);  // the whole fleet's cost, not the subset's

  OptimalAssignmentOptions one_robot;
  one_robot.robots = {1};
  one_robot.respect_queue_room = true;  // R1 has two places for three orders
  Result<BatchAssignment> none = BruteForceAssignment(s, orders, one_robot);
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.error().code, ErrorCode::kUnreachable);
  one_robot.respect_queue_room = false;
  EXPECT_TRUE(BruteForceAssignment(s, orders, one_robot).ok());

  OptimalAssignmentOptions bad;
  bad.robots = {2, 0};
  EXPECT_EQ(BruteForceAssignment(s, orders, bad).error().code, ErrorCode::kInvalidArgument);
  bad.robots = {7};
  EXPECT_EQ(BruteForceAssignment(s, orders, bad).error().code, ErrorCode::kNotFound);

  // 12^6 maps within the limit, a stop that is already true: ends after the first 4,096.
  std::vector<FleetRobot> many;
  for (int i = 0; i < 12; ++i) many.push_back({"R" + std::to_string(i), Pt(*map, "0,0"), 0.0});
  FleetState big = MakeFleet(map, routes, many);
  std::vector<Order> six(6, orders[0]);
  OptimalAssignmentOptions stopped;
  stopped.max_maps = 3'000'000;
  stopped.stop = [] { return true; };
  Result<BatchAssignment> cut = BruteForceAssignment(big, six, stopped);
  ASSERT_FALSE(cut.ok());
  EXPECT_EQ(cut.error().message, "brute force: stopped after 4096 maps");
}

}  // namespace
}  // namespace dispatch::engine

namespace dispatch::engine {
namespace {

// OneToOneAssignment against every injective map of the smaller side into the larger, each
// costed by BatchCost on the orders it serves (empty queues cost nothing), on both shapes.
TEST(OptimalAssignmentTest, OneToOneServesTheCheapestOrdersWhateverTheShape) {
  auto map = Grid(5, 5, 1.0, 5, {{0, 4}, {4, 4}, {2, 2}, {4, 0}}, {{0, 0}, {2, 4}});
  auto routes = Routes(map);
  const std::vector<PointId> picks = {Pt(*map, "0,4"), Pt(*map, "4,4"), Pt(*map, "2,2"), Pt(*map, "4,0")};
  const std::vector<PointId> drops = {Pt(*map, "0,0"), Pt(*map, "2,4")};
  int more_orders = 0;
  for (int seed = 0; seed < 40; ++seed) {
    std::mt19937 rng(seed + 1000);
    const std::size_t m = 1 + rng() % 3;
    const std::size_t n = 1 + rng() % 5;
    std::vector<FleetRobot> robots;
    for (std::size_t i = 0; i < m; ++i) {
      robots.push_back({"R" + std::to_string(i), static_cast<PointId>(rng() % map->point_count()), 0.0});
    }
    std::vector<Order> orders;
    for (std::size_t k = 0; k < n; ++k) {
      orders.push_back(MakeOrder("o" + std::to_string(k), {picks[rng() % picks.size()]}, drops[rng() % drops.size()],
                                 false, static_cast<double>(k)));
    }
    FleetState s = MakeFleet(map, routes, robots);
    std::vector<std::size_t> all(m);
    for (std::size_t r = 0; r < m; ++r) all[r] = r;
    Result<BatchAssignment> got = OneToOneAssignment(s, orders, all);
    ASSERT_TRUE(got.ok()) << got.error().message;
    // Every injective map serving min(n, m) orders: robot_of_order with distinct robots.
    double best = INFINITY;
    std::vector<std::size_t> assign(n, kNoRobot);
    auto cost_of = [&](const std::vector<std::size_t>& a) {
      std::vector<Order> served;
      std::vector<std::size_t> by;
      for (std::size_t k = 0; k < n; ++k) {
        if (a[k] == kNoRobot) continue;
        served.push_back(orders[k]);
        by.push_back(a[k]);
      }
      Result<double> c = BatchCost(s, served, by);
      return c.ok() ? *c : INFINITY;
    };
    auto visit = [&](auto&& self, std::size_t k, std::vector<bool>& used, std::size_t count) -> void {
      if (k == n) {
        if (count == std::min(n, m)) best = std::min(best, cost_of(assign));
        return;
      }
      assign[k] = kNoRobot;
      self(self, k + 1, used, count);
      for (std::size_t r = 0; r < m; ++r) {
        if (used[r]) continue;
        used[r] = true;
        assign[k] = r;
        self(self, k + 1, used, count + 1);
        used[r] = false;
        assign[k] = kNoRobot;
      }
    };
    std::vector<bool> used(m, false);
    visit(visit, 0, used, 0);
    std::size_t served = 0;
    std::vector<bool> taken(m, false);
    for (std::size_t r : got->robot_of_order) {
      if (r == kNoRobot) continue;
      ++served;
      EXPECT_FALSE(taken[r]) << "seed " << seed;
      taken[r] = true;
    }
    EXPECT_EQ(served, std::min(n, m)) << "seed " << seed;
    EXPECT_NEAR(cost_of(got->robot_of_order), best, 1e-6) << "seed " << seed;
    EXPECT_NEAR(got->cost, best, 1e-6) << "seed " << seed;
    if (n > m) ++more_orders;
  }
  EXPECT_GT(more_orders, 10);
}

}  // namespace
}  // namespace dispatch::engine
