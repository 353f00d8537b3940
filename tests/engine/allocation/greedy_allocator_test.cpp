#include "engine/allocation/greedy_allocator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "allocation_test_util.h"
#include "engine/allocation/auction_allocator.h"
#include "engine/allocation/bid.h"

namespace dispatch::engine {
namespace {

using testing_util::Grid;
using testing_util::MakeFleet;
using testing_util::MakeOrder;
using testing_util::Pt;
using testing_util::Routes;

class GreedyTest : public ::testing::Test {
 protected:
  void SetUp() override {
    map_ = Grid(10, 1, 1.0, 5, {{2, 0}, {3, 0}, {8, 0}}, {{0, 0}, {9, 0}});
    routes_ = Routes(map_);
  }
  std::shared_ptr<const WarehouseMap> map_;
  std::shared_ptr<const RouteTable> routes_;
};

TEST_F(GreedyTest, NearestIdleThenEarliestFree) {
  // R1 at 1,0 (near the picks), R2 at 6,0, R3 at 9,0.
  FleetState s = MakeFleet(map_, routes_, {{"R1", Pt(*map_, "1,0"), 0.0},
                                           {"R2", Pt(*map_, "6,0"), 0.0},
                                           {"R3", Pt(*map_, "9,0"), 0.0}});
  GreedyAllocator greedy;
  const PointId p2 = Pt(*map_, "2,0"), p3 = Pt(*map_, "3,0"), d0 = Pt(*map_, "0,0");
  Result<AwardExplanation> a = greedy.Allocate(MakeOrder("a", {p2}, d0), s);
  ASSERT_TRUE(a.ok());
  EXPECT_EQ(a->strategy, "greedy-nearest-idle");
  EXPECT_EQ(a->winners, std::vector<std::string>{"R1"});
  ASSERT_EQ(a->bids.size(), 3u);
  EXPECT_DOUBLE_EQ(a->bids[0].bid, 1.0);  // travel time to the first pick
  EXPECT_DOUBLE_EQ(a->bids[1].bid, 4.0);
  EXPECT_EQ(a->bids[1].t_w, 0.0);
  // R1 is busy now (and would be nearer from its drop 0,0 than R3): the idle R2 wins.
  Result<AwardExplanation> b = greedy.Allocate(MakeOrder("b", {p3}, d0), s);
  ASSERT_TRUE(b.ok());
  EXPECT_EQ(b->winners, std::vector<std::string>{"R2"});
  Result<AwardExplanation> c = greedy.Allocate(MakeOrder("c", {p3}, d0), s);
  ASSERT_TRUE(c.ok());
  EXPECT_EQ(c->winners, std::vector<std::string>{"R3"});
  // Nobody idle: the robot that is free earliest. R1: 1 + 5 + 2 + 5 = 13; R2: 3+5+3+5 = 16.
  EXPECT_DOUBLE_EQ(s.summary(0).end_time, 13.0);
  Result<AwardExplanation> d = greedy.Allocate(MakeOrder("d", {Pt(*map_, "8,0")}, d0), s);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d->winners, std::vector<std::string>{"R1"});
  EXPECT_NE(d->reason.find("free at 13.00"), std::string::npos) << d->reason;
}

TEST_F(GreedyTest, FormationTakesTheThreeFirstByTheSameRule) {
  FleetState s = MakeFleet(map_, routes_, {{"R1", Pt(*map_, "9,0"), 0.0},
                                           {"R2", Pt(*map_, "1,0"), 0.0},
                                           {"R3", Pt(*map_, "5,0"), 0.0},
                                           {"R4", Pt(*map_, "2,0"), 0.0}});
  GreedyAllocator greedy;
  Result<AwardExplanation> a =
      greedy.Allocate(MakeOrder("f", {Pt(*map_, "3,0")}, Pt(*map_, "9,0"), true), s);
  ASSERT_TRUE(a.ok()) << a.error().message;
  // Distances to 3,0: R1 6, R2 2, R3 2, R4 1 -> R4, then R2 (robot order), R3.
  EXPECT_EQ(a->winners, (std::vector<std::string>{"R4", "R2", "R3"}));
  EXPECT_TRUE(s.queue(0).empty());
  for (std::size_t r = 1; r < 4; ++r) EXPECT_EQ(s.queue(r).size(), 1u);
}

// Orders queued over the whole fleet.
std::size_t Queued(const FleetState& s) {
  std::size_t n = 0;
  for (std::size_t r = 0; r < s.robot_count(); ++r) n += s.queue(r).size();
  return n;
}

// AllocationConfig::max_queue: a robot whose queue is full does not bid, for either strategy,
// single or formation orders; with nobody left with room the order is not allocated.
TEST_F(GreedyTest, ARobotWithAFullQueueDoesNotBid) {
  AllocationConfig config;
  config.max_queue = 1;
  const PointId p2 = Pt(*map_, "2,0"), p3 = Pt(*map_, "3,0"), d0 = Pt(*map_, "0,0");
  GreedyAllocator greedy;
  AuctionAllocator auction;
  for (Allocator* strategy : {static_cast<Allocator*>(&greedy), static_cast<Allocator*>(&auction)}) {
    SCOPED_TRACE(std::string(strategy->name()));
    FleetState s = MakeFleet(map_, routes_, {{"R1", Pt(*map_, "1,0"), 0.0}, {"R2", Pt(*map_, "6,0"), 0.0},
                                             {"R3", Pt(*map_, "9,0"), 0.0}, {"R4", Pt(*map_, "8,0"), 0.0}},
                             config);
    auto a = strategy->Allocate(MakeOrder("a", {p2}, d0), s);
    ASSERT_TRUE(a.ok()) << a.error().message;
    EXPECT_EQ(a->winners, std::vector<std::string>{"R1"});
    // R1 is full: the next order near it goes to another robot, and R1's bid says why.
    auto b = strategy->Allocate(MakeOrder("b", {p3}, d0), s);
    ASSERT_TRUE(b.ok()) << b.error().message;
    EXPECT_NE(b->winners.front(), "R1");
    EXPECT_TRUE(b->bids[0].queue_full);
    EXPECT_FALSE(b->bids[0].reachable);
    EXPECT_EQ(DescribeBid(b->bids[0]), "R1 has a full queue");
    // Two robots left with room: a formation cannot be formed, and nothing changes.
    auto f = strategy->Allocate(MakeOrder("f", {p3}, d0, true), s);
    EXPECT_FALSE(f.ok());
    EXPECT_EQ(Queued(s), 2u);
    // One more single order, then every robot is full.
    ASSERT_TRUE(strategy->Allocate(MakeOrder("c", {p3}, d0), s).ok());
    ASSERT_TRUE(strategy->Allocate(MakeOrder("d", {p3}, d0), s).ok());
    EXPECT_FALSE(strategy->Allocate(MakeOrder("e", {p3}, d0), s).ok());
  }
}

// AllocationConfig::formation_max_queue: a robot holding that many orders still takes
// single-robot orders but joins no formation, as leader or companion, for either strategy;
// with too few robots left free the formation waits.
TEST_F(GreedyTest, ARobotWithQueuedWorkJoinsNoFormation) {
  AllocationConfig config;
  config.formation_max_queue = 1;
  const PointId p2 = Pt(*map_, "2,0"), p3 = Pt(*map_, "3,0"), d0 = Pt(*map_, "0,0");
  GreedyAllocator greedy;
  AuctionAllocator auction;
  for (Allocator* strategy : {static_cast<Allocator*>(&greedy), static_cast<Allocator*>(&auction)}) {
    SCOPED_TRACE(std::string(strategy->name()));
    FleetState s = MakeFleet(map_, routes_, {{"R1", Pt(*map_, "1,0"), 0.0}, {"R2", Pt(*map_, "6,0"), 0.0},
                                             {"R3", Pt(*map_, "9,0"), 0.0}, {"R4", Pt(*map_, "8,0"), 0.0},
                                             {"R5", Pt(*map_, "7,0"), 0.0}},
                             config);
    ASSERT_TRUE(strategy->Allocate(MakeOrder("a", {p2}, d0), s).ok());
    EXPECT_EQ(s.queue(0).size(), 1u);  // R1, the nearest
    // R1 still takes single orders (the limit is for formations only) ...
    auto b = strategy->Allocate(MakeOrder("b", {p2}, d0), s);
    ASSERT_TRUE(b.ok()) << b.error().message;
    EXPECT_FALSE(b->bids[0].queue_full);
    // ... but the nearest robot to the pick joins no formation: its bid says its queue is full.
    auto f = strategy->Allocate(MakeOrder("f", {p3}, d0, true), s);
    ASSERT_TRUE(f.ok()) << f.error().message;
    EXPECT_EQ(f->winners.size(), 3u);
    EXPECT_EQ(std::count(f->winners.begin(), f->winners.end(), "R1"), 0);
    EXPECT_TRUE(f->bids[0].queue_full);
    // Four robots hold work now, one is free: the next formation is not formed, nothing changes.
    const std::size_t queued = Queued(s);
    EXPECT_FALSE(strategy->Allocate(MakeOrder("g", {p3}, d0, true), s).ok());
    EXPECT_EQ(Queued(s), queued);
  }
}

TEST_F(GreedyTest, TooFewRobotsForAFormation) {
  FleetState s = MakeFleet(map_, routes_, {{"R1", 0, 0.0}, {"R2", 1, 0.0}});
  GreedyAllocator greedy;
  Result<AwardExplanation> a =
      greedy.Allocate(MakeOrder("f", {Pt(*map_, "3,0")}, Pt(*map_, "9,0"), true), s);
  ASSERT_FALSE(a.ok());
  EXPECT_EQ(a.error().code, ErrorCode::kFailedPrecondition);
  EXPECT_TRUE(s.queue(0).empty());
}

}  // namespace
}  // namespace dispatch::engine
