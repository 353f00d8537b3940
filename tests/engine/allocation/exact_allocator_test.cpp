// The exact assignment as an allocation strategy: on batches that fit one chunk in a fleet no
// larger than the candidates it gives BatchCost's optimum; larger batches go in chunks within
// the map limit; formations, orders no robot reaches and a spent budget go to the auction.
#include "engine/allocation/exact_allocator.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "allocation_test_util.h"
#include "engine/allocation/optimal_assignment.h"

namespace dispatch::engine {
namespace {

using testing_util::Grid;
using testing_util::MakeFleet;
using testing_util::MakeOrder;
using testing_util::Pt;
using testing_util::Routes;

struct Awarded {
  std::string order, strategy, reason, error;
  std::vector<std::string> winners;
  double bid = 0.0;  // the winner's B
};

std::vector<Awarded> RunBatch(ExactAllocator& allocator, const std::vector<Order>& orders, FleetState& fleet) {
  std::vector<const Order*> batch;
  for (const Order& o : orders) batch.push_back(&o);
  std::vector<Awarded> out;
  allocator.AllocateBatch(batch, fleet, [&](const Order& o, Result<AwardExplanation> a) {
    out.push_back(a.ok() ? Awarded{o.id, a->strategy, a->reason, "", a->winners, a->bids.empty() ? 0.0 : a->bids[0].bid}
                         : Awarded{o.id, "", "", a.error().message, {}, 0.0});
  });
  return out;
}

// The bid sum is the auction's own criterion: on the auction's awards (zeta = 0: no traffic
// term) it is the sum of the winning bids; the exact assignment's is never above it, and is the
// minimum over every map. The queue totals objective is BatchCost's yardstick.
TEST(ExactAllocatorTest, OnSmallBatchesItIsTheOptimumAndNeverAboveTheAuction) {
  auto map = Grid(6, 6, 1.0, 6, {{0, 5}, {5, 5}, {2, 2}, {5, 0}, {3, 4}}, {{0, 0}, {2, 5}});
  auto routes = Routes(map);
  const std::vector<PointId> picks = {Pt(*map, "0,5"), Pt(*map, "5,5"), Pt(*map, "2,2"),
                                      Pt(*map, "5,0"), Pt(*map, "3,4")};
  const std::vector<PointId> drops = {Pt(*map, "0,0"), Pt(*map, "2,5")};
  int below_auction = 0;
  for (int seed = 0; seed < 40; ++seed) {
    std::mt19937 rng(static_cast<unsigned>(seed));
    const int m = 2 + static_cast<int>(rng() % 3);  // <= candidates: every robot is searched
    const int n = 2 + static_cast<int>(rng() % 4);
    AllocationConfig c;
    c.zeta = 0.0;
    std::vector<FleetRobot> robots;
    for (int i = 0; i < m; ++i) {
      robots.push_back({"R" + std::to_string(i), static_cast<PointId>(rng() % map->point_count()), 0.0});
    }
    std::vector<Order> orders;
    for (int k = 0; k < n; ++k) {
      std::vector<PointId> p = {picks[rng() % picks.size()]};
      if (rng() % 3 == 0) p.push_back(picks[rng() % picks.size()]);
      Order o = MakeOrder("o" + std::to_string(k), p, drops[rng() % drops.size()], false, k);
      o.work_time = 1.0 + static_cast<double>(rng() % 3);
      orders.push_back(o);
    }
    FleetState fleet = MakeFleet(map, routes, robots, c);
    OptimalAssignmentOptions bid_sum;
    bid_sum.objective = BatchObjective::kBidSum;
    Result<BatchAssignment> best = BruteForceAssignment(fleet, orders, bid_sum);
    ASSERT_TRUE(best.ok()) << best.error().message;

    ExactAllocator exact;
    const std::vector<Awarded> awards = RunBatch(exact, orders, fleet);
    ASSERT_EQ(awards.size(), orders.size());
    for (std::size_t k = 0; k < awards.size(); ++k) {
      ASSERT_EQ(awards[k].order, orders[k].id) << "seed " << seed;  // committed in batch order
      ASSERT_EQ(awards[k].winners.size(), 1u) << awards[k].error;
      EXPECT_EQ(awards[k].strategy, "exact");
      EXPECT_EQ(awards[k].winners[0], fleet.robot_id(best->robot_of_order[k])) << "seed " << seed;
    }
    double winning = 0.0;  // the awards' own B, summed
    for (const Awarded& a : awards) winning += a.bid;
    EXPECT_NEAR(winning, best->cost, 1e-6) << "seed " << seed;

    FleetState by_auction = MakeFleet(map, routes, robots, c);
    AuctionAllocator auction;
    std::vector<std::size_t> auction_map;
    double auction_bids = 0.0;
    for (const OrderAllocation& a : AllocateAll(auction, orders, by_auction)) {
      ASSERT_TRUE(a.award.ok());
      auction_map.push_back(*by_auction.FindRobot(a.award->winners[0]));
      for (const Bid& b : a.award->bids) {
        if (b.robot == a.award->winners[0]) auction_bids += b.bid;
      }
    }
    FleetState before = MakeFleet(map, routes, robots, c);
    Result<double> auction_cost = BatchCost(before, orders, auction_map, BatchObjective::kBidSum);
    ASSERT_TRUE(auction_cost.ok());
    EXPECT_NEAR(*auction_cost, auction_bids, 1e-6) << "seed " << seed;  // the same criterion
    EXPECT_GE(auction_bids, best->cost - 1e-9) << "seed " << seed;
    if (auction_bids > best->cost + 1e-9) ++below_auction;

    ExactOptions totals;
    totals.objective = BatchObjective::kQueueTotals;
    ExactAllocator yardstick(totals);
    FleetState again = MakeFleet(map, routes, robots, c);
    const std::vector<Awarded> by_totals = RunBatch(yardstick, orders, again);
    ASSERT_EQ(by_totals.size(), orders.size());
    FleetState fresh = MakeFleet(map, routes, robots, c);
    Result<BatchAssignment> optimum = BruteForceAssignment(fresh, orders);
    ASSERT_TRUE(optimum.ok());
    for (std::size_t k = 0; k < by_totals.size(); ++k) {
      ASSERT_EQ(by_totals[k].winners.size(), 1u);
      EXPECT_EQ(by_totals[k].winners[0], fresh.robot_id(optimum->robot_of_order[k])) << "seed " << seed;
    }
  }
  EXPECT_GT(below_auction, 0);  // the instances are not all ones the auction already solves
}

TEST(ExactAllocatorTest, ALargeBatchGoesInChunksWithinTheMapLimit) {
  auto map = Grid(10, 10, 1.0, 10, {{2, 2}, {7, 7}, {2, 7}, {7, 2}, {5, 5}, {0, 9}, {1, 2}, {8, 7}},
                  {{0, 0}, {9, 9}});
  auto routes = Routes(map);
  FleetState fleet = MakeFleet(map, routes,
                               {{"R1", Pt(*map, "1,1"), 0.0}, {"R2", Pt(*map, "8,8"), 0.0},
                                {"R3", Pt(*map, "1,8"), 0.0}, {"R4", Pt(*map, "8,1"), 0.0},
                                {"R5", Pt(*map, "5,4"), 0.0}, {"R6", Pt(*map, "4,5"), 0.0}});
  const std::vector<std::string> at = {"2,2", "7,7", "2,7", "7,2", "5,5", "0,9", "1,2", "8,7"};
  std::vector<Order> orders;
  for (int k = 0; k < 14; ++k) {
    orders.push_back(MakeOrder("o" + std::to_string(k), {Pt(*map, at[static_cast<std::size_t>(k) % at.size()])},
                               Pt(*map, k % 2 ? "0,0" : "9,9"), false, k));
  }
  ExactOptions options;
  options.candidates = 3;
  options.max_maps = 1000;
  ExactAllocator exact(options);
  const std::vector<Awarded> awards = RunBatch(exact, orders, fleet);
  ASSERT_EQ(awards.size(), orders.size());
  std::set<std::string> seen;
  std::size_t queued = 0;
  for (const Awarded& a : awards) {
    EXPECT_TRUE(seen.insert(a.order).second) << a.order << " twice";
    ASSERT_EQ(a.winners.size(), 1u) << a.order << ": " << a.error;
    EXPECT_EQ(a.strategy, "exact");
    // "exact over K orders and R robots": R ^ K within the limit, K >= 1.
    std::size_t k = 0, r = 0;
    ASSERT_EQ(std::sscanf(a.reason.c_str(), "exact over %zu orders and %zu robots", &k, &r), 2) << a.reason;
    EXPECT_GE(k, 1u);
    EXPECT_LE(std::pow(static_cast<double>(r), static_cast<double>(k)), 1000.0) << a.reason;
    EXPECT_LT(k, orders.size()) << "one chunk would exceed the limit";
  }
  for (std::size_t r = 0; r < fleet.robot_count(); ++r) queued += fleet.queue(r).size();
  EXPECT_EQ(queued, orders.size());
  FleetState again = MakeFleet(map, routes,
                               {{"R1", Pt(*map, "1,1"), 0.0}, {"R2", Pt(*map, "8,8"), 0.0},
                                {"R3", Pt(*map, "1,8"), 0.0}, {"R4", Pt(*map, "8,1"), 0.0},
                                {"R5", Pt(*map, "5,4"), 0.0}, {"R6", Pt(*map, "4,5"), 0.0}});
  ExactAllocator second(options);
  const std::vector<Awarded> repeat = RunBatch(second, orders, again);
  ASSERT_EQ(repeat.size(), awards.size());
  for (std::size_t k = 0; k < awards.size(); ++k) EXPECT_EQ(repeat[k].winners, awards[k].winners);
}

TEST(ExactAllocatorTest, FormationsFullQueuesBadOrdersAndASpentBudgetGoElsewhere) {
  auto map = Grid(6, 6, 1.0, 6, {{2, 2}, {4, 4}, {1, 4}}, {{0, 0}, {5, 5}});
  auto routes = Routes(map);
  AllocationConfig c;
  c.max_queue = 1;
  const std::vector<FleetRobot> robots = {{"R1", Pt(*map, "1,1"), 0.0}, {"R2", Pt(*map, "4,5"), 0.0},
                                          {"R3", Pt(*map, "5,1"), 0.0}, {"R4", Pt(*map, "0,5"), 0.0}};
  FleetState fleet = MakeFleet(map, routes, robots, c);
  const std::vector<Order> orders = {
      MakeOrder("team", {Pt(*map, "2,2")}, Pt(*map, "5,5"), /*formation=*/true),
      MakeOrder("bad", {static_cast<PointId>(9999)}, Pt(*map, "0,0")),
      MakeOrder("a", {Pt(*map, "4,4")}, Pt(*map, "0,0")),
      MakeOrder("b", {Pt(*map, "1,4")}, Pt(*map, "5,5"))};
  ExactAllocator exact;
  std::map<std::string, Awarded> got;
  for (Awarded& a : RunBatch(exact, orders, fleet)) got[a.order] = a;
  ASSERT_EQ(got.size(), 4u);
  EXPECT_EQ(got["team"].strategy.rfind("auction", 0), 0u) << got["team"].strategy;
  EXPECT_EQ(got["team"].winners.size(), 3u);
  EXPECT_NE(got["bad"].error.find("unknown point id 9999"), std::string::npos) << got["bad"].error;
  // The team took three robots' only place: a and b share the one robot left, which has room
  // for one of them; the other finds no robot with room and the auction says so.
  const bool a_first = !got["a"].winners.empty();
  const Awarded& placed = a_first ? got["a"] : got["b"];
  const Awarded& waits = a_first ? got["b"] : got["a"];
  EXPECT_EQ(placed.strategy, "exact");
  ASSERT_EQ(placed.winners.size(), 1u);
  for (const std::string& w : got["team"].winners) EXPECT_NE(placed.winners[0], w) << placed.reason;
  EXPECT_TRUE(waits.winners.empty());
  EXPECT_FALSE(waits.error.empty());

  // No budget: everything goes to the auction, order by order.
  ExactOptions none;
  none.budget = std::chrono::milliseconds(0);
  ExactAllocator spent(none);
  FleetState fresh = MakeFleet(map, routes, robots);
  const std::vector<Awarded> awards = RunBatch(spent, {orders[2], orders[3]}, fresh);
  ASSERT_EQ(awards.size(), 2u);
  for (const Awarded& a : awards) EXPECT_EQ(a.strategy.rfind("auction", 0), 0u) << a.strategy;
}

}  // namespace
}  // namespace dispatch::engine
