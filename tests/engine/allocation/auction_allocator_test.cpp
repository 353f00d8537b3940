#include "engine/allocation/auction_allocator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

#include "allocation_test_util.h"
#include "engine/fleet/task_table.h"
#include "engine/map/chu2024_floor.h"

namespace dispatch::engine {
namespace {

using testing_util::Grid;
using testing_util::MakeFleet;
using testing_util::MakeOrder;
using testing_util::Pt;
using testing_util::Routes;

void ExpectBidTerms(const Bid& b, const AllocationConfig& c) {
  ASSERT_TRUE(b.reachable) << b.robot;
  EXPECT_DOUBLE_EQ(b.t_t, b.t_d + b.t_w) << b.robot;                            // eq. (2)
  EXPECT_DOUBLE_EQ(b.x, c.zeta * b.flow) << b.robot;                            // eq. (5)
  EXPECT_DOUBLE_EQ(b.bid, c.alpha * b.t_t + c.beta * b.t_d + b.x) << b.robot;  // eq. (4)
}

std::size_t ArgMin(const std::vector<Bid>& bids, bool with_traffic, const AllocationConfig& c) {
  std::size_t best = bids.size();
  double best_v = INFINITY;
  for (std::size_t i = 0; i < bids.size(); ++i) {
    if (!bids[i].reachable) continue;
    const double v = c.alpha * bids[i].t_t + c.beta * bids[i].t_d + (with_traffic ? bids[i].x : 0);
    if (v < best_v) {
      best_v = v;
      best = i;
    }
  }
  return best;
}

class AuctionGridTest : public ::testing::Test {
 protected:
  void SetUp() override {
    map_ = Grid(8, 8, 1.0, 4, {{1, 6}, {6, 6}, {3, 3}, {7, 1}, {2, 0}},
                {{0, 7}, {7, 7}, {0, 0}});
    routes_ = Routes(map_);
    picks_ = {Pt(*map_, "1,6"), Pt(*map_, "6,6"), Pt(*map_, "3,3"), Pt(*map_, "7,1"),
              Pt(*map_, "2,0")};
    drops_ = {Pt(*map_, "0,7"), Pt(*map_, "7,7"), Pt(*map_, "0,0")};
  }
  std::vector<FleetRobot> RandomRobots(std::mt19937& rng, int n) {
    std::vector<FleetRobot> robots;
    for (int i = 0; i < n; ++i) {
      robots.push_back({"R" + std::to_string(i + 1),
                        static_cast<PointId>(rng() % map_->point_count()), 0.0});
    }
    return robots;
  }
  Order RandomOrder(std::mt19937& rng, int k, bool formation = false) {
    std::vector<PointId> picks;
    const int n = 1 + static_cast<int>(rng() % 2);
    for (int j = 0; j < n; ++j) picks.push_back(picks_[rng() % picks_.size()]);
    return MakeOrder("o" + std::to_string(k), picks, drops_[rng() % drops_.size()], formation, k);
  }
  std::shared_ptr<const WarehouseMap> map_;
  std::shared_ptr<const RouteTable> routes_;
  std::vector<PointId> picks_, drops_;
};

TEST_F(AuctionGridTest, BidsEqualTheFormulaAndTheQueueTotals) {
  std::mt19937 rng(11);
  AllocationConfig c;
  c.alpha = 0.3;
  c.beta = 0.7;
  c.zeta = 50.0;
  FleetState s = MakeFleet(map_, routes_, RandomRobots(rng, 5), c);
  AuctionAllocator auction;
  for (int k = 0; k < 8; ++k) {
    const Order o = RandomOrder(rng, k);
    Result<PlanTask> task = PrepareOrder(o, s);
    ASSERT_TRUE(task.ok());
    const std::vector<Bid> bids = auction.ComputeBids(s, *task);
    ASSERT_EQ(bids.size(), s.robot_count());
    for (std::size_t i = 0; i < bids.size(); ++i) {
      ExpectBidTerms(bids[i], c);
      EXPECT_EQ(bids[i].robot, s.robot_id(i));
      const QueueSummary& q = s.summary(i);
      // eq. (3) over the whole queue: T_d from table costs, T_w = n_c t_w.
      EXPECT_NEAR(bids[i].t_d, q.travel_time + routes_->Cost(q.end_point, o.picks[0]) +
                                   s.TaskTravelTime(*task), 1e-9);
      EXPECT_NEAR(bids[i].t_w, q.work_time + o.picks.size() * o.work_time + c.drop_time.value_or(o.work_time), 1e-9);
      EXPECT_GE(bids[i].flow, 0.0);
    }
    Result<AwardExplanation> award = auction.Allocate(o, s);
    ASSERT_TRUE(award.ok()) << award.error().message;
    EXPECT_EQ(award->bids.size(), bids.size());
    for (std::size_t i = 0; i < bids.size(); ++i) EXPECT_EQ(award->bids[i].bid, bids[i].bid);
  }
}

TEST_F(AuctionGridTest, WinnerMinimisesTheBid) {
  for (double zeta : {0.0, 100.0}) {
    for (int seed = 0; seed < 20; ++seed) {
      std::mt19937 rng(seed);
      AllocationConfig c;
      c.zeta = zeta;
      FleetState s = MakeFleet(map_, routes_, RandomRobots(rng, 2 + seed % 5), c);
      AuctionAllocator auction;
      for (int k = 0; k < 5; ++k) {
        Result<AwardExplanation> a = auction.Allocate(RandomOrder(rng, k), s);
        ASSERT_TRUE(a.ok()) << a.error().message;
        const std::size_t best = ArgMin(a->bids, zeta > 0, c);  // first minimum: robot order
        ASSERT_EQ(a->winners.size(), 1u);
        EXPECT_EQ(a->winners[0], a->bids[best].robot) << "seed " << seed << " order " << k;
        EXPECT_EQ(a->reason.rfind(a->winners[0] + ": lowest bid", 0), 0u) << a->reason;
        for (const Bid& b : a->bids) ExpectBidTerms(b, c);
        if (zeta == 0.0) {
          for (const Bid& b : a->bids) EXPECT_EQ(b.x, 0.0);
        }
      }
    }
  }
}

TEST_F(AuctionGridTest, AQueuedRobotBidsForItsWholeQueue) {
  FleetState s = MakeFleet(map_, routes_, {{"R1", Pt(*map_, "0,0"), 0.0}});
  AuctionAllocator auction;
  Result<AwardExplanation> a1 = auction.Allocate(MakeOrder("a", {Pt(*map_, "2,0")}, Pt(*map_, "0,7")), s);
  ASSERT_TRUE(a1.ok());
  const double end1 = s.summary(0).end_time;
  const double td1 = a1->bids[0].t_d;
  Result<AwardExplanation> a2 = auction.Allocate(MakeOrder("b", {Pt(*map_, "1,6")}, Pt(*map_, "7,7")), s);
  ASSERT_TRUE(a2.ok());
  EXPECT_DOUBLE_EQ(a2->bids[0].ready_time, end1);
  EXPECT_DOUBLE_EQ(a2->bids[0].t_d, td1 + 2.0 + 7.0);  // 0,7 -> 1,6 -> 7,7
  EXPECT_DOUBLE_EQ(a2->bids[0].t_w, 4 * kDefaultWorkTime);  // two picks and two drops (t_w each)
  ASSERT_EQ(s.queue(0).size(), 2u);
  EXPECT_DOUBLE_EQ(s.queue(0)[1].start_time, end1);
}

// Two robots 10 m from the pick on either side; three robots parked in the west zone. Equal
// times: zeta = 0 picks the first robot (west), zeta > 0 the east one (empty zone).
TEST(AuctionTrafficTest, CrowdedZoneLosesWhenTrafficCounts) {
  MapBuilder b("crowd");
  b.SetFloor({-1, -1}, {21, 9});
  b.AddRectZone("west", {-1, -1}, {9, 9});
  b.AddRectZone("middle", {9, -1}, {11, 6});
  b.AddRectZone("east", {11, -1}, {21, 9});
  b.AddRectZone("north", {9, 6}, {11, 9});
  b.AddPoint("A", {0, 0}, PointKind::kLane);
  b.AddPoint("B", {5, 0}, PointKind::kLane);
  b.AddPoint("P", {10, 0}, PointKind::kPick);
  b.AddPoint("C", {15, 0}, PointKind::kLane);
  b.AddPoint("D", {20, 0}, PointKind::kLane);
  b.AddPoint("Q", {10, 5}, PointKind::kDrop);
  b.AddPoint("E", {0, 8}, PointKind::kPark);
  for (auto [u, v] : {std::pair{"A", "B"}, {"B", "P"}, {"P", "C"}, {"C", "D"}, {"P", "Q"}, {"A", "E"}}) {
    b.AddPath(u, v, std::nullopt, 0.0, true);
  }
  auto map = testing_util::Share(b.Build());
  auto routes = Routes(map);
  const std::vector<FleetRobot> robots = {{"R1", Pt(*map, "A"), 0.0}, {"R2", Pt(*map, "D"), 0.0},
                                          {"R3", Pt(*map, "E"), 0.0}, {"R4", Pt(*map, "E"), 0.0},
                                          {"R5", Pt(*map, "E"), 0.0}};
  const Order o = MakeOrder("o", {Pt(*map, "P")}, Pt(*map, "Q"));
  AuctionAllocator auction;
  {
    AllocationConfig c;
    c.zeta = 0.0;
    FleetState s = MakeFleet(map, routes, robots, c);
    Result<AwardExplanation> a = auction.Allocate(o, s);
    ASSERT_TRUE(a.ok());
    EXPECT_EQ(a->bids[0].bid, a->bids[1].bid);
    EXPECT_EQ(a->winners[0], "R1");
    EXPECT_NE(a->reason.find("tied with R2"), std::string::npos) << a->reason;
  }
  {
    AllocationConfig c;
    FleetState s = MakeFleet(map, routes, robots, c);
    Result<AwardExplanation> a = auction.Allocate(o, s);
    ASSERT_TRUE(a.ok());
    EXPECT_EQ(a->bids[0].t_t, a->bids[1].t_t);
    const ZoneId west = *map->FindZone("west");
    const double s_west = map->zones()[static_cast<std::size_t>(west)].area;
    // R1 meets the 3 parked robots in the west zone: N_west,max = 3 (eq. (6)).
    bool saw_west = false;
    for (auto [z, n] : a->bids[0].peaks) {
      if (z == west) {
        EXPECT_EQ(n, 3);
        saw_west = true;
      }
    }
    EXPECT_TRUE(saw_west);
    EXPECT_GE(a->bids[0].flow, 3.0 / s_west);
    EXPECT_LT(a->bids[1].flow, a->bids[0].flow);
    EXPECT_EQ(a->winners[0], "R2") << a->reason;
  }
}

TEST_F(AuctionGridTest, FormationLeaderIsTheLowestBidderAndCompanionsReachFirst) {
  for (double zeta : {0.0, 100.0}) {
    for (int seed = 0; seed < 15; ++seed) {
      std::mt19937 rng(100 + seed);
      AllocationConfig c;
      c.zeta = zeta;
      FleetState s = MakeFleet(map_, routes_, RandomRobots(rng, 3 + seed % 5), c);
      AuctionAllocator auction;
      for (int k = 0; k < 4; ++k) {
        const Order o = RandomOrder(rng, k, /*formation=*/k % 2 == 0);
        Result<AwardExplanation> a = auction.Allocate(o, s);
        ASSERT_TRUE(a.ok()) << a.error().message;
        if (!o.formation) continue;
        ASSERT_EQ(a->winners.size(), 3u);
        EXPECT_EQ(std::set<std::string>(a->winners.begin(), a->winners.end()).size(), 3u);
        const std::size_t lead = ArgMin(a->bids, true, c);
        EXPECT_EQ(a->winners[0], a->bids[lead].robot);
        // companion_bids: every robot but the leader, in robot order.
        ASSERT_EQ(a->companion_bids.size(), s.robot_count() - 1);
        std::vector<const Bid*> sorted;
        for (const Bid& b : a->companion_bids) {
          EXPECT_NE(b.robot, a->winners[0]);
          ExpectBidTerms(b, c);
          sorted.push_back(&b);
        }
        std::stable_sort(sorted.begin(), sorted.end(),
                         [](const Bid* x, const Bid* y) { return x->bid < y->bid; });
        EXPECT_EQ(a->winners[1], sorted[0]->robot);
        EXPECT_EQ(a->winners[2], sorted[1]->robot);
        // All three queues end with this order.
        for (const std::string& w : a->winners) {
          const std::size_t r = *s.FindRobot(w);
          EXPECT_EQ(s.queue(r).back().order_id, o.id);
          EXPECT_EQ(s.queue(r).back().team, a->winners);
        }
      }
    }
  }
}

// Large fleets price only the bids that can decide the award (price_every_bid_up_to): the
// winners, the reason and every priced bid equal those of pricing every bid, and each
// unpriced bid's lower bound already exceeds the bids that decided.
TEST_F(AuctionGridTest, PricingOnlyBidsThatCanWinGivesTheSameAward) {
  std::size_t unpriced = 0;
  for (double zeta : {0.0, 100.0}) {
    for (int seed = 0; seed < 12; ++seed) {
      std::mt19937 rng(300 + seed);
      const std::vector<FleetRobot> robots = RandomRobots(rng, 6 + seed % 7);
      AllocationConfig full_config;
      full_config.zeta = zeta;
      AllocationConfig pruned_config = full_config;
      pruned_config.price_every_bid_up_to = 1;
      FleetState full = MakeFleet(map_, routes_, robots, full_config);
      FleetState pruned = MakeFleet(map_, routes_, robots, pruned_config);
      AuctionAllocator a_full, a_pruned;
      for (int k = 0; k < 8; ++k) {
        const Order o = RandomOrder(rng, k, /*formation=*/k % 3 == 2);
        Result<AwardExplanation> f = a_full.Allocate(o, full);
        Result<AwardExplanation> p = a_pruned.Allocate(o, pruned);
        ASSERT_TRUE(f.ok()) << f.error().message;
        ASSERT_TRUE(p.ok()) << p.error().message;
        EXPECT_EQ(p->winners, f->winners) << "seed " << seed << " order " << k;
        EXPECT_EQ(p->reason, f->reason);
        ASSERT_EQ(p->bids.size(), f->bids.size());
        const double winning = f->bids[*full.FindRobot(f->winners[0])].bid;
        for (std::size_t i = 0; i < p->bids.size(); ++i) {
          const Bid& b = p->bids[i];
          EXPECT_EQ(b.t_d, f->bids[i].t_d);
          EXPECT_EQ(b.t_w, f->bids[i].t_w);
          if (b.priced) {
            EXPECT_EQ(b.bid, f->bids[i].bid);
            EXPECT_EQ(b.flow, f->bids[i].flow);
          } else {
            ++unpriced;
            EXPECT_TRUE(f->bids[i].priced);
            // A lower bound with its own terms: F over part of the route.
            EXPECT_EQ(b.x, full_config.zeta * b.flow);
            EXPECT_EQ(b.bid, BidValue(full_config.alpha, full_config.beta, b.t_t, b.t_d, b.x));
            EXPECT_LE(b.flow, f->bids[i].flow);
            EXPECT_LE(b.bid, f->bids[i].bid);
            EXPECT_GT(b.bid, winning);
            EXPECT_TRUE(b.peaks.empty());
            EXPECT_NE(DescribeBid(b).find("could not win"), std::string::npos);
          }
        }
      }
    }
  }
  EXPECT_GT(unpriced, 100u);  // the pruning is exercised
}

TEST(AuctionErrorTest, BadOrdersFailAndOthersStillAllocate) {
  MapBuilder b("trap");
  b.SetFloor({-1, -1}, {9, 5});
  b.AddRectZone("z", {-1, -1}, {9, 5});
  b.AddPoint("S1", {0, 0}, PointKind::kPark);
  b.AddPoint("S2", {2, 0}, PointKind::kPark);
  b.AddPoint("P", {4, 0}, PointKind::kPick);
  b.AddPoint("D", {8, 0}, PointKind::kDrop);
  b.AddPoint("T", {4, 4}, PointKind::kPick);  // one-way out only: nobody reaches it
  b.AddPoint("X", {8, 4}, PointKind::kDrop);  // one-way out only: no order can end there
  b.AddPath("S1", "S2", std::nullopt, 0.0, true);
  b.AddPath("S2", "P", std::nullopt, 0.0, true);
  b.AddPath("P", "D", std::nullopt, 0.0, true);
  b.AddPath("T", "P");
  b.AddPath("X", "D");
  MapBuildOptions mo;
  mo.check_service_connectivity = false;
  auto map = testing_util::Share(b.Build(mo));
  auto routes = Routes(map);
  const PointId P = Pt(*map, "P"), D = Pt(*map, "D"), T = Pt(*map, "T"), X = Pt(*map, "X");
  FleetState s = MakeFleet(map, routes, {{"R1", Pt(*map, "S1"), 0.0}, {"R2", Pt(*map, "S2"), 0.0}});
  std::vector<Order> orders = {
      MakeOrder("empty", {}, D, false, 1),         MakeOrder("trap-pick", {T}, D, false, 2),
      MakeOrder("trap-drop", {P}, X, false, 3),    MakeOrder("team", {P}, D, true, 4),
      MakeOrder("good", {P}, D, false, 5),         MakeOrder("unknown", {999}, D, false, 6),
  };
  orders.back().priority = -1;  // allocated last
  AuctionAllocator auction;
  const std::vector<OrderAllocation> out = AllocateAll(auction, orders, s);
  ASSERT_EQ(out.size(), 6u);
  auto code = [&](std::size_t k) { return out[k].award.error().code; };
  auto msg = [&](std::size_t k) { return out[k].award.error().message; };
  EXPECT_EQ(out[0].order_id, "empty");
  EXPECT_EQ(code(0), ErrorCode::kInvalidArgument);
  EXPECT_NE(msg(0).find("order empty: no pick points"), std::string::npos);
  EXPECT_EQ(code(1), ErrorCode::kUnreachable);
  EXPECT_NE(msg(1).find("no robot can reach the first pick 'T'"), std::string::npos) << msg(1);
  EXPECT_EQ(code(2), ErrorCode::kUnreachable);
  EXPECT_NE(msg(2).find("drop 'X' is unreachable"), std::string::npos) << msg(2);
  EXPECT_EQ(code(3), ErrorCode::kFailedPrecondition);
  EXPECT_NE(msg(3).find("needs 3 robots, the fleet has 2"), std::string::npos) << msg(3);
  ASSERT_TRUE(out[4].award.ok());
  EXPECT_EQ(out[4].award->winners, std::vector<std::string>{"R2"});
  EXPECT_EQ(out[5].order_id, "unknown");
  EXPECT_EQ(code(5), ErrorCode::kNotFound);
  // Only the good order was committed.
  EXPECT_EQ(s.queue(0).size() + s.queue(1).size(), 1u);
}

TEST(AuctionOrderTest, AllocateAllSortsByPriorityThenArrival) {
  auto map = Grid(4, 1, 1.0, 4, {{1, 0}}, {{3, 0}});
  auto routes = Routes(map);
  FleetState s = MakeFleet(map, routes, {{"R1", Pt(*map, "0,0"), 0.0}});
  std::vector<Order> orders = {MakeOrder("late", {Pt(*map, "1,0")}, Pt(*map, "3,0"), false, 5),
                               MakeOrder("b", {Pt(*map, "1,0")}, Pt(*map, "3,0"), false, 1),
                               MakeOrder("a", {Pt(*map, "1,0")}, Pt(*map, "3,0"), false, 1),
                               MakeOrder("urgent", {Pt(*map, "1,0")}, Pt(*map, "3,0"), false, 9)};
  orders[3].priority = 2;
  AuctionAllocator auction;
  const std::vector<OrderAllocation> out = AllocateAll(auction, orders, s);
  std::vector<std::string> ids;
  for (const auto& a : out) ids.push_back(a.order_id);
  EXPECT_EQ(ids, (std::vector<std::string>{"urgent", "a", "b", "late"}));
  ASSERT_EQ(s.queue(0).size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) EXPECT_EQ(s.queue(0)[k].order_id, ids[k]);
}

// Seed 000 Table 2 on the reconstructed Chu2024 floor, robots R1..R18 at P1..P18.
class Chu2024Table2Test : public ::testing::TestWithParam<double> {};

TEST_P(Chu2024Table2Test, AllocatesEveryTask) {
  Result<WarehouseMap> floor = BuildChu2024Floor();
  ASSERT_TRUE(floor.ok()) << floor.error().message;
  auto map = testing_util::Share(std::move(floor));
  auto routes = Routes(map);
  std::vector<FleetRobot> robots;
  for (const ParkingStation& st : map->stations()) {
    if (st.name.size() < 2 || st.name[0] != 'P') continue;
    robots.push_back({"R" + st.name.substr(1), Pt(*map, "park-" + st.name), 0.0});
  }
  std::sort(robots.begin(), robots.end(), [](const FleetRobot& a, const FleetRobot& b) {
    return std::stoi(a.id.substr(1)) < std::stoi(b.id.substr(1));
  });
  ASSERT_EQ(robots.size(), 18u);
  std::ifstream in(std::string(DISPATCH_SHARED_DIR) + "/scenarios/chu2024-table2.csv");
  ASSERT_TRUE(in) << "cannot read chu2024-table2.csv under " << DISPATCH_SHARED_DIR;
  std::stringstream text;
  text << in.rdbuf();
  Result<std::vector<OrderRequest>> requests = ParseTaskTable(text.str());
  ASSERT_TRUE(requests.ok()) << requests.error().message;
  std::vector<Order> orders;
  for (std::size_t k = 0; k < requests->size(); ++k) {
    Result<Order> o = ResolveOrder(*map, (*requests)[k]);
    ASSERT_TRUE(o.ok()) << o.error().message;
    Order order = std::move(o).value();
    order.created_time = static_cast<double>(k);
    orders.push_back(std::move(order));
  }
  AllocationConfig c;
  c.zeta = GetParam();
  FleetState s = MakeFleet(map, routes, robots, c);
  AuctionAllocator auction;
  const std::vector<OrderAllocation> out = AllocateAll(auction, orders, s);
  ASSERT_EQ(out.size(), 8u);
  std::set<std::string> used;
  for (std::size_t k = 0; k < out.size(); ++k) {
    ASSERT_TRUE(out[k].award.ok()) << out[k].award.error().message;
    const AwardExplanation& a = *out[k].award;
    EXPECT_EQ(a.order_id, orders[k].id);
    EXPECT_EQ(a.bids.size(), 18u);
    EXPECT_EQ(a.winners.size(), orders[k].formation ? 3u : 1u);
    EXPECT_EQ(std::set<std::string>(a.winners.begin(), a.winners.end()).size(), a.winners.size());
    for (const Bid& b : a.bids) ExpectBidTerms(b, c);
    used.insert(a.winners.begin(), a.winners.end());
    std::string line = "T" + a.order_id + ":";
    for (const std::string& w : a.winners) line += " " + w;
    std::cout << "[zeta=" << c.zeta << "] " << line << " | " << a.reason << "\n";
  }
  // 4 formations x 3 + 4 singles = 16 robots: with 18 idle robots none needs a second task.
  EXPECT_EQ(used.size(), 16u);
  for (std::size_t r = 0; r < s.robot_count(); ++r) {
    for (std::size_t k = 1; k < s.plan(r).waypoints.size(); ++k) {
      EXPECT_GE(s.plan(r).waypoints[k].eta + 1e-9, s.plan(r).waypoints[k - 1].departure());
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Zeta, Chu2024Table2Test, ::testing::Values(0.0, 100.0));

}  // namespace
}  // namespace dispatch::engine
