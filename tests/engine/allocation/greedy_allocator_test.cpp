#include "engine/allocation/greedy_allocator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "allocation_test_util.h"

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
