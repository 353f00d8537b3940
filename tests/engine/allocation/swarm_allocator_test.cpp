// PSO-GA as an allocation strategy: a batch of orders, each reaching the sink once as it is
// committed, robots' shares in their plan's order, formations by the auction.
#include "engine/allocation/swarm_allocator.h"

#include <gtest/gtest.h>

#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "allocation_test_util.h"

namespace dispatch::engine {
namespace {

using testing_util::Grid;
using testing_util::MakeFleet;
using testing_util::MakeOrder;
using testing_util::Pt;
using testing_util::Routes;

struct Award {
  std::string order, strategy, error;
  std::vector<std::string> winners;
  bool operator==(const Award&) const = default;
};

class SwarmAllocatorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    map_ = Grid(10, 10, 1.0, 5, {{2, 2}, {7, 7}, {2, 7}, {7, 2}, {5, 5}, {0, 9}, {1, 2}, {8, 7}},
                {{0, 0}, {9, 9}});
    routes_ = Routes(map_);
  }
  FleetState Fleet() const {
    return MakeFleet(map_, routes_, {{"R1", P("1,1"), 0.0}, {"R2", P("8,8"), 0.0},
                                     {"R3", P("1,8"), 0.0}, {"R4", P("8,1"), 0.0}});
  }
  PointId P(const std::string& name) const { return Pt(*map_, name); }
  std::vector<Award> Run(const std::vector<Order>& orders, FleetState& fleet) const {
    std::vector<const Order*> batch;
    for (const Order& o : orders) batch.push_back(&o);
    std::vector<Award> out;
    SwarmAllocator allocator;
    allocator.AllocateBatch(batch, fleet, [&](const Order& o, Result<AwardExplanation> a) {
      out.push_back(a.ok() ? Award{o.id, a->strategy, "", a->winners} : Award{o.id, "", a.error().message, {}});
    });
    return out;
  }
  std::shared_ptr<const WarehouseMap> map_;
  std::shared_ptr<const RouteTable> routes_;
};

TEST_F(SwarmAllocatorTest, EveryOrderReachesTheSinkOnceAndQueuesFollowTheCommits) {
  const std::vector<Order> orders = {
      MakeOrder("a", {P("2,2")}, P("0,0")), MakeOrder("b", {P("7,7")}, P("9,9")),
      MakeOrder("c", {P("2,7")}, P("9,9")), MakeOrder("f", {P("5,5")}, P("0,0"), /*formation=*/true),
      MakeOrder("d", {P("7,2")}, P("0,0")), MakeOrder("e", {P("0,9")}, P("0,0")),
      MakeOrder("g", {P("1,2")}, P("9,9"))};
  FleetState fleet = Fleet();
  const std::vector<Award> awards = Run(orders, fleet);
  ASSERT_EQ(awards.size(), orders.size());
  std::set<std::string> seen;
  std::vector<std::vector<std::string>> committed(fleet.robot_count());
  for (const Award& a : awards) {
    EXPECT_TRUE(seen.insert(a.order).second) << a.order << " twice";
    EXPECT_EQ(a.error, "");
    if (a.order == "f") {
      EXPECT_EQ(a.strategy.rfind("auction", 0), 0u) << a.strategy;  // formations: the auction
      EXPECT_EQ(a.winners.size(), 3u);
    } else {
      EXPECT_EQ(a.strategy, "psoga");
      EXPECT_EQ(a.winners.size(), 1u);
    }
    for (const std::string& w : a.winners) committed[*fleet.FindRobot(w)].push_back(a.order);
  }
  for (std::size_t r = 0; r < fleet.robot_count(); ++r) {
    std::vector<std::string> queued;
    for (const QueuedTask& q : fleet.queue(r)) queued.push_back(q.order_id);
    EXPECT_EQ(queued, committed[r]) << fleet.robot_id(r);
  }
  FleetState again = Fleet();
  EXPECT_EQ(Run(orders, again), awards);  // seeded: the same batch, the same awards
}

// Four orders, each at one robot's door: the joint plan gives each robot its own.
TEST_F(SwarmAllocatorTest, EachRobotTakesTheOrderAtItsDoor) {
  const std::vector<Order> orders = {
      MakeOrder("near-R2", {P("8,7")}, P("9,9")), MakeOrder("near-R1", {P("1,2")}, P("0,0")),
      MakeOrder("near-R4", {P("7,2")}, P("0,0")), MakeOrder("near-R3", {P("2,7")}, P("9,9"))};
  FleetState fleet = Fleet();
  for (const Award& a : Run(orders, fleet)) {
    ASSERT_EQ(a.winners.size(), 1u) << a.order << ": " << a.error;
    EXPECT_EQ("near-" + a.winners[0], a.order);
  }
}

TEST_F(SwarmAllocatorTest, AnOrderThatCannotBeAllocatedIsNamedTheOthersAre) {
  const std::vector<Order> orders = {MakeOrder("bad", {static_cast<PointId>(9999)}, P("0,0")),
                                     MakeOrder("ok", {P("2,2")}, P("0,0"))};
  FleetState fleet = Fleet();
  const std::vector<Award> awards = Run(orders, fleet);
  ASSERT_EQ(awards.size(), 2u);
  EXPECT_EQ(awards[0].order, "bad");
  EXPECT_NE(awards[0].error.find("unknown point id 9999"), std::string::npos) << awards[0].error;
  EXPECT_EQ(awards[1].order, "ok");
  EXPECT_EQ(awards[1].winners, std::vector<std::string>{"R1"});
  // One order alone (Allocate): the same strategy, a batch of one.
  SwarmAllocator allocator;
  const auto one = allocator.Allocate(MakeOrder("one", {P("7,7")}, P("9,9")), fleet);
  ASSERT_TRUE(one.ok()) << one.error().message;
  EXPECT_EQ(one->winners, std::vector<std::string>{"R2"});
}

// An order on an island no robot reaches: the auction says why; the others are allocated (the
// search never sees it, and a search whose every plan is infinite still returns a plan).
TEST(SwarmAllocatorIsland, AnOrderNoRobotReachesGoesToTheAuction) {
  MapBuilder b("island");
  b.SetFloor({-1.0, -1.0}, {10.0, 1.0});
  b.AddRectZone("z", {-1.0, -1.0}, {10.0, 1.0});
  b.AddPoint("a", {0.0, 0.0}, PointKind::kLane);
  b.AddPoint("p", {1.0, 0.0}, PointKind::kPick);
  b.AddPoint("d", {2.0, 0.0}, PointKind::kDrop);
  b.AddPoint("q", {6.0, 0.0}, PointKind::kPick);  // the island: q <-> e
  b.AddPoint("e", {7.0, 0.0}, PointKind::kDrop);
  b.AddPath("a", "p", std::nullopt, 0.0, true);
  b.AddPath("p", "d", std::nullopt, 0.0, true);
  b.AddPath("q", "e", std::nullopt, 0.0, true);
  MapBuildOptions options;
  options.check_service_connectivity = false;
  auto map = testing_util::Share(b.Build(options));
  FleetState fleet = MakeFleet(map, Routes(map), {{"R1", Pt(*map, "a"), 0.0}});
  const std::vector<Order> orders = {MakeOrder("island", {Pt(*map, "q")}, Pt(*map, "e")),
                                     MakeOrder("ok", {Pt(*map, "p")}, Pt(*map, "d"))};
  std::vector<const Order*> batch = {&orders[0], &orders[1]};
  std::map<std::string, Result<AwardExplanation>> got;
  SwarmAllocator allocator;
  allocator.AllocateBatch(batch, fleet, [&](const Order& o, Result<AwardExplanation> a) { got.emplace(o.id, std::move(a)); });
  ASSERT_EQ(got.size(), 2u);
  ASSERT_FALSE(got.at("island").ok());
  EXPECT_EQ(got.at("island").error().code, ErrorCode::kUnreachable) << got.at("island").error().message;
  ASSERT_TRUE(got.at("ok").ok()) << got.at("ok").error().message;
  EXPECT_EQ(got.at("ok")->winners, std::vector<std::string>{"R1"});

  SwarmProblem p;  // every plan infinite
  p.robots = {{0, 0.0}};
  p.tasks = {{1, 0.0}, {2, 0.0}};
  p.distance = [](PointId, PointId) { return std::numeric_limits<double>::infinity(); };
  const auto plan = PlanSwarm(p, SwarmOptions{});
  ASSERT_TRUE(plan.ok()) << plan.error().message;
  EXPECT_EQ(plan->fitness, std::numeric_limits<double>::infinity());
  ASSERT_EQ(plan->sequences.size(), 1u);
  EXPECT_EQ(plan->sequences[0].size(), 2u);
}

}  // namespace
}  // namespace dispatch::engine
