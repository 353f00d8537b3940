// TrafficController: point reservations, corridors (head-on), grants, standing robots and the
// timeouts, driven like the simulator drives it (positions and time only). Deadlock breaking,
// giving way and nudges: traffic_controller_deadlock_test.cpp.
#include "engine/traffic/traffic_controller.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "engine/map/map_builder.h"
#include "tests/engine/traffic/controller_test_support.h"

namespace dispatch::engine {
namespace {

using testing_traffic::Grid;
using testing_traffic::Make;
using testing_traffic::P;
using testing_traffic::Route;
using testing_traffic::Step;

// A robot off the floor that still stands somewhere (a formation member left in its slot when
// its team broke up) keeps strangers off the points around it - not its mates - until it is
// placed again; it was invisible, and strangers drove up to such robots (0.000 m, 200 random
// orders with 30% formations, seed 6).
TEST(TrafficControllerTest, ARobotStandingOffTheFloorKeepsStrangersAway) {
  auto map = Grid({"....."});
  TrafficController ctl = Make(map);
  const std::size_t s = *ctl.AddRobot("S", P(*map, "c4"));
  ctl.Remove(s);
  ctl.SetGroup(s, 7);
  ctl.SetStanding(s, map->point(P(*map, "c2")).position + Eigen::Vector2d(0.25, 0.0));
  EXPECT_FALSE(ctl.AddRobot("B", P(*map, "c2")).ok());  // 0.25 m from it
  const std::size_t a = *ctl.AddRobot("A", P(*map, "c0"));
  ASSERT_TRUE(ctl.SetRoute(a, Route(*map, {"c0", "c1", "c2"})).ok());
  EXPECT_EQ(ctl.Request(a, 0.0), TrafficDecision::kGo);  // c1 is 1.25 m from it
  ctl.LeftPoint(a);
  ctl.Arrived(a, 1.0);
  EXPECT_EQ(ctl.Request(a, 1.0), TrafficDecision::kWait);
  EXPECT_EQ(ctl.WaitsOn(a), static_cast<int>(s));
  ctl.SetGroup(a, 7);  // a mate may come closer
  EXPECT_EQ(ctl.Request(a, 2.0), TrafficDecision::kGo) << ctl.why(a);
  ctl.Arrived(a, 3.0);
  // Placed again (on c4): it stands there now, no longer at c2.
  ctl.SetGroup(a, 0);
  ASSERT_TRUE(ctl.Place(s, P(*map, "c4")).ok());
  ASSERT_TRUE(ctl.SetRoute(a, Route(*map, {"c2", "c1"})).ok());
  EXPECT_EQ(ctl.Request(a, 4.0), TrafficDecision::kGo) << ctl.why(a);
}

TEST(TrafficControllerTest, PointsAreExclusive) {
  auto map = Grid({"....."});
  TrafficController ctl = Make(map);
  const std::size_t a = *ctl.AddRobot("A", P(*map, "c1"));
  const std::size_t b = *ctl.AddRobot("B", P(*map, "c0"));
  EXPECT_FALSE(ctl.AddRobot("C", P(*map, "c1")).ok());  // c1 is A's
  ASSERT_TRUE(ctl.SetRoute(a, Route(*map, {"c1", "c2", "c3"})).ok());
  ASSERT_TRUE(ctl.SetRoute(b, Route(*map, {"c0", "c1", "c2"})).ok());
  EXPECT_EQ(ctl.Request(b, 0.0), TrafficDecision::kWait);
  EXPECT_NE(ctl.why(b).find("held by A"), std::string::npos) << ctl.why(b);
  EXPECT_EQ(ctl.Request(a, 0.0), TrafficDecision::kGo);
  EXPECT_EQ(ctl.Next(a), P(*map, "c2"));
  // The remaining route starts at the point it stands at (c1, until it arrives at c2).
  EXPECT_EQ(ctl.RemainingRoute(a), Route(*map, {"c1", "c2", "c3"}));
  EXPECT_TRUE(ctl.RemainingRouteIs(a, Route(*map, {"c1", "c2", "c3"})));
  EXPECT_FALSE(ctl.RemainingRouteIs(a, Route(*map, {"c2", "c3"})));
  EXPECT_FALSE(ctl.RemainingRouteIs(a, {}));
  EXPECT_EQ(ctl.Request(b, 0.1), TrafficDecision::kWait);  // A still holds c1 while driving
  ctl.Arrived(a, 1.0);
  EXPECT_EQ(ctl.Request(b, 1.0), TrafficDecision::kGo);
  // A route that does not start where the robot stands is refused.
  EXPECT_FALSE(ctl.SetRoute(a, Route(*map, {"c3", "c4"})).ok());
}

// The route epoch moves on with every change of a remaining route (set, reached, removed,
// placed) and not otherwise, and no two robots share one: the gate trusts an unchanged epoch
// instead of comparing routes every step.
TEST(TrafficControllerTest, RouteEpochChangesExactlyWithTheRemainingRoute) {
  auto map = Grid({"....."});
  TrafficController ctl = Make(map);
  const std::size_t a = *ctl.AddRobot("A", P(*map, "c1"));
  const std::size_t b = *ctl.AddRobot("B", P(*map, "c4"));
  std::set<std::uint64_t> seen = {ctl.RouteEpoch(a), ctl.RouteEpoch(b)};
  EXPECT_EQ(seen.size(), 2u);
  auto moved_on = [&](std::size_t r) {
    const bool fresh = seen.insert(ctl.RouteEpoch(r)).second;
    return fresh;
  };
  ASSERT_TRUE(ctl.SetRoute(a, Route(*map, {"c1", "c2", "c3"})).ok());
  EXPECT_TRUE(moved_on(a));
  const std::uint64_t set = ctl.RouteEpoch(a);
  EXPECT_EQ(ctl.Request(a, 0.0), TrafficDecision::kGo);  // driving: the remaining route is the same
  ctl.LeftPoint(a);
  EXPECT_EQ(ctl.RouteEpoch(a), set);
  EXPECT_TRUE(ctl.RemainingRouteIs(a, Route(*map, {"c1", "c2", "c3"})));
  ctl.Arrived(a, 1.0);
  EXPECT_TRUE(moved_on(a));
  EXPECT_TRUE(ctl.RemainingRouteIs(a, Route(*map, {"c2", "c3"})));
  ctl.Remove(a);
  EXPECT_TRUE(moved_on(a));
  ASSERT_TRUE(ctl.Place(a, P(*map, "c0")).ok());
  EXPECT_TRUE(moved_on(a));
  const std::uint64_t b_epoch = ctl.RouteEpoch(b);
  ASSERT_TRUE(ctl.SetRoute(a, Route(*map, {"c0", "c1"})).ok());
  EXPECT_TRUE(moved_on(a));
  EXPECT_EQ(ctl.RouteEpoch(b), b_epoch);  // another robot's changes leave it alone
}

TEST(TrafficControllerTest, HeadOnWithoutDetourWaitsAndIsLogged) {
  auto map = Grid({"......"});
  TrafficController ctl = Make(map);
  const std::size_t a = *ctl.AddRobot("A", P(*map, "c0"));
  const std::size_t b = *ctl.AddRobot("B", P(*map, "c5"));
  ASSERT_TRUE(ctl.SetRoute(a, Route(*map, {"c0", "c1", "c2"})).ok());
  ASSERT_TRUE(ctl.SetRoute(b, Route(*map, {"c5", "c4", "c3"})).ok());
  EXPECT_EQ(ctl.Request(a, 0.0), TrafficDecision::kGo);  // A reserves the lane eastwards
  EXPECT_EQ(ctl.Request(b, 0.0), TrafficDecision::kWait);
  EXPECT_NE(ctl.why(b).find("head-on"), std::string::npos) << ctl.why(b);
  ASSERT_EQ(ctl.stats().head_on.size(), 1u);
  EXPECT_EQ(ctl.stats().head_on[0].robot, "B");
  EXPECT_EQ(ctl.stats().head_on[0].oncoming, "A");
  EXPECT_FALSE(ctl.stats().head_on[0].replanned);
  EXPECT_GT(ctl.stats().head_on[0].wait_estimate, 0.0);
  // A is done at c2 and leaves the corridor only when it leaves the map's lane: here it
  // stays inside, so B keeps waiting; removing A frees the lane.
  ctl.Arrived(a, 1.0);
  EXPECT_EQ(ctl.Request(a, 1.0), TrafficDecision::kGo);
  ctl.Arrived(a, 2.0);
  EXPECT_EQ(ctl.Request(b, 2.0), TrafficDecision::kWait);
  ctl.Remove(a);
  EXPECT_EQ(ctl.Request(b, 3.0), TrafficDecision::kGo);
}

TEST(TrafficControllerTest, IntersectionNeedsAGrantAndReleasesItBehind) {
  MapBuilder b("cross");
  b.SetFloor({-1, -1}, {11, 11});
  b.AddRectZone("z", {-1, -1}, {11, 11});
  b.AddPoint("W", {2, 5}, PointKind::kLane);
  b.AddPoint("C1", {5, 5}, PointKind::kIntersection);
  b.AddPoint("C2", {6, 5}, PointKind::kIntersection);
  b.AddPoint("E", {9, 5}, PointKind::kLane);
  b.AddPoint("S", {6, 2}, PointKind::kLane);
  b.AddPoint("N", {6, 9}, PointKind::kLane);
  b.AddPath("W", "C1");
  b.AddPath("C1", "C2");
  b.AddPath("C2", "E");
  b.AddPath("S", "C2");
  b.AddPath("C2", "N");
  b.AddIntersection("X", {"C1", "C2"}, {"W", "S"});
  MapBuildOptions options;
  options.check_service_connectivity = false;
  auto built = b.Build(options);
  ASSERT_TRUE(built.ok()) << built.error().message;
  auto map = std::make_shared<const WarehouseMap>(std::move(built).value());
  TrafficController ctl = Make(map);
  const std::size_t a = *ctl.AddRobot("A", P(*map, "W"));
  const std::size_t c = *ctl.AddRobot("B", P(*map, "S"));
  ASSERT_TRUE(ctl.SetRoute(a, Route(*map, {"W", "C1", "C2", "E"})).ok());
  ASSERT_TRUE(ctl.SetRoute(c, Route(*map, {"S", "C2", "N"})).ok());
  EXPECT_EQ(ctl.Request(a, 0.0), TrafficDecision::kGo);  // grant W -> E
  ctl.Arrived(a, 1.0);                                   // A in I_w at C1; C2 is free
  EXPECT_EQ(ctl.Request(c, 1.0), TrafficDecision::kWait);  // crossing movement: no grant
  EXPECT_NE(ctl.why(c).find("grant"), std::string::npos) << ctl.why(c);
  EXPECT_EQ(ctl.Request(a, 1.0), TrafficDecision::kGo);
  ctl.Arrived(a, 2.0);
  EXPECT_EQ(ctl.Request(a, 2.0), TrafficDecision::kGo);
  EXPECT_EQ(ctl.Request(c, 2.0), TrafficDecision::kWait);  // A still inside (drives to E)
  ctl.Arrived(a, 3.0);                                     // A has left I_w
  EXPECT_EQ(ctl.Request(c, 3.0), TrafficDecision::kGo);
  EXPECT_EQ(ctl.stats().grants, 2u);

  // A robot placed on a point inside I_w (a restart, a formation broken up there) holds the
  // grant from then on: nobody crosses around it until it has left.
  TrafficController again = Make(map);
  const std::size_t d = *again.AddRobot("D", P(*map, "C1"));
  const std::size_t s = *again.AddRobot("S", P(*map, "S"));
  ASSERT_TRUE(again.SetRoute(s, Route(*map, {"S", "C2", "N"})).ok());
  EXPECT_EQ(again.Request(s, 0.0), TrafficDecision::kWait);
  EXPECT_NE(again.why(s).find("grant"), std::string::npos) << again.why(s);
  EXPECT_EQ(again.grants().Holders(0), std::vector<std::string>{"D"});
  ASSERT_TRUE(again.SetRoute(d, Route(*map, {"C1", "C2", "E"})).ok());
  EXPECT_EQ(again.Request(d, 0.0), TrafficDecision::kGo);  // inside and out: no request
  again.Arrived(d, 1.0);
  EXPECT_EQ(again.Request(s, 1.0), TrafficDecision::kWait);  // D still inside, at C2
  EXPECT_EQ(again.Request(d, 1.0), TrafficDecision::kGo);
  again.Arrived(d, 2.0);
  EXPECT_EQ(again.Request(s, 2.0), TrafficDecision::kGo);
  // The same after Remove and Place (S, granted, has not entered yet).
  again.Remove(d);
  ASSERT_TRUE(again.Place(d, P(*map, "C1")).ok());
  EXPECT_EQ(again.grants().Holders(0), (std::vector<std::string>{"S", "D"}));

  // A robot off the floor takes a grant over for where it stands (a formation member in its
  // slot when its team breaks up) before the holder lets it go: the waiting crosser is not
  // granted in between; placed outside the intersection, it lets the grant go.
  TrafficController third = Make(map);
  const std::size_t team = *third.AddRobot("T", P(*map, "C1"));
  const std::size_t member = *third.AddRobot("M", P(*map, "E"));
  const std::size_t cross = *third.AddRobot("X", P(*map, "S"));
  third.Remove(member);
  ASSERT_TRUE(third.SetRoute(cross, Route(*map, {"S", "C2", "N"})).ok());
  EXPECT_EQ(third.Request(cross, 0.0), TrafficDecision::kWait);  // T stands inside
  third.HoldGrantAt(member, P(*map, "C1"));
  third.Remove(team);
  EXPECT_EQ(third.Request(cross, 1.0), TrafficDecision::kWait);
  EXPECT_EQ(third.grants().Holders(0), std::vector<std::string>{"M"});
  ASSERT_TRUE(third.Place(member, P(*map, "E")).ok());  // it stands outside after all
  EXPECT_EQ(third.Request(cross, 2.0), TrafficDecision::kGo);
}

// Wang2019 §3.2 step 4: a robot waiting on a held point waits T_w2, then re-plans a route
// around the point if one exists. Cells of a 5-wide grid are c<row * 5 + column>.
TEST(TrafficControllerTest, AWaitOnAHeldPointRePlansAfterTw2) {
  auto map = Grid({".....", ".@@@.", "....."});
  TrafficControllerConfig c;
  c.t_w2 = 20.0;
  TrafficController ctl = Make(map, c);
  const std::size_t a = *ctl.AddRobot("A", P(*map, "c0"));
  ASSERT_TRUE(ctl.AddRobot("B", P(*map, "c2")).ok());  // stands in the way, no route
  ASSERT_TRUE(ctl.SetRoute(a, Route(*map, {"c0", "c1", "c2", "c3", "c4"})).ok());
  ASSERT_EQ(ctl.Request(a, 0.0), TrafficDecision::kGo);
  ctl.Arrived(a, 1.0);
  EXPECT_EQ(ctl.Request(a, 1.0), TrafficDecision::kWait);
  EXPECT_NE(ctl.why(a).find("'c2' held by B"), std::string::npos) << ctl.why(a);
  EXPECT_EQ(ctl.Request(a, 20.9), TrafficDecision::kWait);  // 19.9 s: not yet
  EXPECT_EQ(ctl.RemainingRoute(a), Route(*map, {"c1", "c2", "c3", "c4"}));
  EXPECT_EQ(ctl.Request(a, 21.0), TrafficDecision::kReplanned);  // 20 s: round the block
  const std::vector<PointId> around = ctl.RemainingRoute(a);
  EXPECT_EQ(around.front(), P(*map, "c1"));
  EXPECT_EQ(around.back(), P(*map, "c4"));
  EXPECT_EQ(std::count(around.begin(), around.end(), P(*map, "c2")), 0);
  EXPECT_EQ(ctl.stats().replans, 1u);
}

// Wang2019 §3.2 step 3 with the single waiting strategy (§4.3): a robot that meets a corridor
// held the other way waits T_w1, then re-plans around it. Two one-cell-wide corridors (rows 1
// and 3, columns 2-5) join open ends; cells of this 8-wide grid are c<row * 8 + column>.
TEST(TrafficControllerTest, AHeadOnWaitRePlansAfterTw1) {
  auto map = Grid({"..@@@@..", "........", "..@@@@..", "........"});
  TrafficControllerConfig c;
  c.t_w1 = 10.0;
  c.head_on = HeadOnPolicy::kAlwaysWait;
  TrafficController ctl = Make(map, c);
  const std::size_t a = *ctl.AddRobot("A", P(*map, "c9"));
  const std::size_t b = *ctl.AddRobot("B", P(*map, "c13"));
  ASSERT_TRUE(ctl.SetRoute(b, Route(*map, {"c13", "c12", "c11", "c10", "c9", "c8"})).ok());
  ASSERT_EQ(ctl.Request(b, 0.0), TrafficDecision::kGo);  // B drives west in the row-1 corridor
  ASSERT_TRUE(ctl.SetRoute(a, Route(*map, {"c9", "c10", "c11", "c12", "c13", "c14", "c15"})).ok());
  EXPECT_EQ(ctl.Request(a, 0.0), TrafficDecision::kWait);
  EXPECT_NE(ctl.why(a).find("head-on"), std::string::npos) << ctl.why(a);
  EXPECT_EQ(ctl.Request(a, 9.9), TrafficDecision::kWait);
  EXPECT_EQ(ctl.Request(a, 10.0), TrafficDecision::kReplanned);
  const std::vector<PointId> around = ctl.RemainingRoute(a);
  EXPECT_EQ(around.back(), P(*map, "c15"));
  EXPECT_EQ(std::count(around.begin(), around.end(), P(*map, "c11")), 0);  // by row 3
  ASSERT_FALSE(ctl.stats().head_on.empty());
  EXPECT_FALSE(ctl.stats().head_on.front().replanned);  // the head-on itself was waited
}

TEST(TrafficControllerTest, RejectsBadConfig) {
  auto map = Grid({".."});
  TrafficControllerConfig c;
  c.t_w1 = 0;
  EXPECT_FALSE(TrafficController::Create(map, c).ok());
  EXPECT_FALSE(TrafficController::Create(nullptr, {}).ok());
}

}  // namespace
}  // namespace dispatch::engine
