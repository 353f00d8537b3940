// TrafficController: point reservations, corridors (head-on), grants, deadlock breaking,
// nudges and blocked robots, driven like the simulator drives it (positions and time only).
#include "engine/traffic/traffic_controller.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "engine/io/movingai_map.h"
#include "engine/map/map_builder.h"

namespace dispatch::engine {
namespace {

std::shared_ptr<const WarehouseMap> Grid(const std::vector<std::string>& rows) {
  std::string text = "type octile\nheight " + std::to_string(rows.size()) + "\nwidth " +
                     std::to_string(rows[0].size()) + "\nmap\n";
  for (const auto& r : rows) text += r + "\n";
  auto map = ParseMovingAiMap(text, "grid");
  if (!map.ok()) throw std::runtime_error(map.error().message);
  return std::make_shared<const WarehouseMap>(std::move(map).value());
}

PointId P(const WarehouseMap& m, const std::string& name) { return *m.FindPoint(name); }

std::vector<PointId> Route(const WarehouseMap& m, std::initializer_list<const char*> names) {
  std::vector<PointId> out;
  for (const char* n : names) out.push_back(P(m, n));
  return out;
}

TrafficController Make(std::shared_ptr<const WarehouseMap> map, TrafficControllerConfig c = {}) {
  auto ctl = TrafficController::Create(std::move(map), c);
  if (!ctl.ok()) throw std::runtime_error(ctl.error().message);
  return std::move(ctl).value();
}

// One "step" of an ideal driver: arcs take one step; standing robots with a route ask.
void Step(TrafficController& ctl, double t) {
  for (std::size_t r = 0; r < ctl.robot_count(); ++r) {
    if (ctl.Next(r) != kNoPoint) {
      ctl.Arrived(r, t);
    } else if (ctl.HasRoute(r)) {
      while (ctl.Request(r, t) == TrafficDecision::kReplanned) {
      }
    }
  }
  ctl.ResolveDeadlocks(t);
}

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

TEST(TrafficControllerTest, SwapOnOpenGridIsADeadlockThatGetsBroken) {
  auto map = Grid({"...", "...", "..."});
  TrafficController ctl = Make(map);
  const std::size_t a = *ctl.AddRobot("A", P(*map, "c3"));
  const std::size_t b = *ctl.AddRobot("B", P(*map, "c4"));
  ASSERT_TRUE(ctl.SetRoute(a, Route(*map, {"c3", "c4", "c5"})).ok());
  ASSERT_TRUE(ctl.SetRoute(b, Route(*map, {"c4", "c3"})).ok());
  EXPECT_EQ(ctl.Request(a, 0.0), TrafficDecision::kWait);
  EXPECT_EQ(ctl.Request(b, 0.0), TrafficDecision::kWait);
  EXPECT_EQ(ctl.ResolveDeadlocks(0.0), 1u);
  EXPECT_EQ(ctl.stats().deadlocks_resolved, 1u);
  double t = 0;
  for (int i = 0; i < 40 && (ctl.HasRoute(a) || ctl.HasRoute(b) || ctl.Next(a) != kNoPoint ||
                             ctl.Next(b) != kNoPoint);
       ++i) {
    Step(ctl, t += 1.0);
  }
  EXPECT_EQ(ctl.At(a), P(*map, "c5"));
  EXPECT_EQ(ctl.At(b), P(*map, "c3"));
  EXPECT_GE(ctl.stats().replans, 1u);
}

// Wang2019 §3.2: with priority_by_release the robot whose task was released later gives way
// in a deadlock; by index (the default) the higher index does, whatever the release times.
TEST(TrafficControllerTest, TheLaterReleasedRobotGivesWayInADeadlock) {
  auto map = Grid({"...", "...", "..."});
  for (bool by_release : {false, true}) {
    SCOPED_TRACE(by_release ? "by release" : "by index");
    TrafficControllerConfig c;
    c.priority_by_release = by_release;
    TrafficController ctl = Make(map, c);
    const std::size_t a = *ctl.AddRobot("A", P(*map, "c3"));
    const std::size_t b = *ctl.AddRobot("B", P(*map, "c4"));
    ctl.SetRank(a, 20.0);  // A's task was released after B's
    ctl.SetRank(b, 10.0);
    const auto route_a = Route(*map, {"c3", "c4", "c5"}), route_b = Route(*map, {"c4", "c3"});
    ASSERT_TRUE(ctl.SetRoute(a, route_a).ok());
    ASSERT_TRUE(ctl.SetRoute(b, route_b).ok());
    EXPECT_EQ(ctl.Request(a, 0.0), TrafficDecision::kWait);
    EXPECT_EQ(ctl.Request(b, 0.0), TrafficDecision::kWait);
    EXPECT_EQ(ctl.ResolveDeadlocks(0.0), 1u);
    const bool a_moved = ctl.RemainingRoute(a) != route_a, b_moved = ctl.RemainingRoute(b) != route_b;
    EXPECT_EQ(a_moved, by_release);
    EXPECT_EQ(b_moved, !by_release);
  }
}

// Wang2019 §3.3 case ②: A (released first) drives west down a lane from c5 to c0, B (released
// later) east from c4 to c6; they meet head-on, each waiting for the other. With
// head_on_give_way B, the waiting robot of lower priority, drives back to the nearest free
// point off A's way - the pocket c8 below c1 - and waits there until A has passed; A drives on
// and never backs. Without it (printed beside) B backs off one point and drives straight back
// into A's way, again and again: neither is through after 60 steps.
TEST(TrafficControllerTest, AWaitingRobotOfLowerPriorityGivesWayOffTheOthersWay) {
  auto map = Grid({".......", "@.@@@@@"});
  for (bool give_way : {false, true}) {
    SCOPED_TRACE(give_way ? "give way" : "back off");
    TrafficControllerConfig c;
    c.priority_by_release = true;
    c.head_on_give_way = give_way;
    TrafficController ctl = Make(map, c);
    const std::size_t a = *ctl.AddRobot("A", P(*map, "c5"));
    const std::size_t b = *ctl.AddRobot("B", P(*map, "c4"));
    ctl.SetRank(a, 10.0);
    ctl.SetRank(b, 20.0);
    ASSERT_TRUE(ctl.SetRoute(a, Route(*map, {"c5", "c4", "c3", "c2", "c1", "c0"})).ok());
    ASSERT_TRUE(ctl.SetRoute(b, Route(*map, {"c4", "c5", "c6"})).ok());
    double t = 0.0, a_done = -1.0, b_done = -1.0;
    bool b_in_pocket = false, a_backed = false;
    PointId a_was = ctl.At(a);
    for (int i = 0; i < 60 && (a_done < 0 || b_done < 0); ++i) {
      Step(ctl, t += 1.0);
      b_in_pocket = b_in_pocket || ctl.At(b) == P(*map, "c8");
      a_backed = a_backed || map->point(ctl.At(a)).position.x() > map->point(a_was).position.x();
      a_was = ctl.At(a);
      if (a_done < 0 && ctl.At(a) == P(*map, "c0") && !ctl.HasRoute(a) && ctl.Next(a) == kNoPoint) a_done = t;
      if (b_done < 0 && ctl.At(b) == P(*map, "c6") && !ctl.HasRoute(b) && ctl.Next(b) == kNoPoint) b_done = t;
    }
    std::printf("%s: A at c0 after %.0f steps, B at c6 after %.0f (-1: not within 60), give-ways %zu, "
                "cycles broken %zu\n", give_way ? "give way" : "back off", a_done, b_done, ctl.stats().give_ways,
                ctl.stats().deadlocks_resolved);
    if (!give_way) continue;
    EXPECT_TRUE(b_in_pocket);
    EXPECT_FALSE(a_backed);
    EXPECT_EQ(ctl.stats().give_ways, 1u);
    EXPECT_GT(a_done, 0.0);
    EXPECT_GT(b_done, a_done);
  }
}

TEST(TrafficControllerTest, IdleRobotInTheWayIsNudgedToASiding) {
  auto map = Grid({".....", "@@.@@"});
  TrafficController ctl = Make(map);
  const std::size_t a = *ctl.AddRobot("A", P(*map, "c0"));
  const std::size_t b = *ctl.AddRobot("B", P(*map, "c2"));  // idle, on A's way
  ASSERT_TRUE(ctl.SetRoute(a, Route(*map, {"c0", "c1", "c2", "c3", "c4"})).ok());
  double t = 0;
  for (int i = 0; i < 30 && ctl.At(a) != P(*map, "c4"); ++i) Step(ctl, t += 1.0);
  EXPECT_EQ(ctl.At(a), P(*map, "c4"));
  EXPECT_EQ(ctl.At(b), P(*map, "c7"));  // the spur below c2
  EXPECT_EQ(ctl.stats().nudges, 1u);
  EXPECT_EQ(ctl.stats().deadlocks_resolved, 0u);
}

// An idle robot the waiter needs is boxed in by idle robots (found on the Wang2019 grid: two
// robots had stepped aside next to a corner drop where a third stood done): they step aside
// first (MakeRoom), then it can, and the waiter gets through.
TEST(TrafficControllerTest, AnIdleRobotBoxedInByIdleRobotsIsMadeRoomFor) {
  auto map = Grid({".....", "@@.@@", "@...@"});
  TrafficController ctl = Make(map);
  const std::size_t a = *ctl.AddRobot("A", P(*map, "c0"));
  const std::size_t b = *ctl.AddRobot("B", P(*map, "c2"));  // idle where A is going
  (void)*ctl.AddRobot("C", P(*map, "c7"));                   // idle below it
  (void)*ctl.AddRobot("D", P(*map, "c3"));                   // idle beside it
  ASSERT_TRUE(ctl.SetRoute(a, Route(*map, {"c0", "c1", "c2"})).ok());
  double t = 0;
  for (int i = 0; i < 60 && ctl.At(a) != P(*map, "c2"); ++i) Step(ctl, t += 1.0);
  EXPECT_EQ(ctl.At(a), P(*map, "c2"));
  EXPECT_NE(ctl.At(b), P(*map, "c2"));
  EXPECT_GE(ctl.stats().nudges, 2u);
}

TEST(TrafficControllerTest, WorkingRobotIsNeverMovedAndAWaiterWithoutDetourIsBlocked) {
  auto map = Grid({"...."});
  TrafficControllerConfig config;
  config.blocked_after = 30.0;
  TrafficController ctl = Make(map, config);
  const std::size_t w = *ctl.AddRobot("W", P(*map, "c2"));
  ctl.SetWorking(w, true, 1e9);
  ctl.SetIdle(w, false);
  const std::size_t b = *ctl.AddRobot("B", P(*map, "c0"));
  ASSERT_TRUE(ctl.SetRoute(b, Route(*map, {"c0", "c1", "c2", "c3"})).ok());
  TrafficDecision last = TrafficDecision::kWait;
  double t = 0;
  for (int i = 0; i < 100 && last != TrafficDecision::kBlocked; ++i) {
    t += 1.0;
    if (ctl.Next(b) != kNoPoint) ctl.Arrived(b, t);
    last = ctl.Request(b, t);
    ctl.ResolveDeadlocks(t);
  }
  EXPECT_EQ(last, TrafficDecision::kBlocked);
  EXPECT_LE(t, 35.0);
  EXPECT_NE(ctl.why(b).find("no alternative"), std::string::npos) << ctl.why(b);
  EXPECT_NE(ctl.why(b).find("held by W"), std::string::npos) << ctl.why(b);
  EXPECT_EQ(ctl.At(w), P(*map, "c2"));
}

TEST(TrafficControllerTest, AnOwnersWaitClosesACycleThatGetsBroken) {
  // W stands at c2 with no route and waits, for its owner, on F (a formation's agent waiting
  // for a member that F holds up); F wants c2. Only with that wait is there a cycle, and F,
  // the one that can act, backs off.
  auto map = Grid({"...."});
  TrafficController ctl = Make(map);
  const std::size_t w = *ctl.AddRobot("W", P(*map, "c2"));
  ctl.SetWorking(w, true, 1e9);
  ctl.SetIdle(w, false);
  const std::size_t f = *ctl.AddRobot("F", P(*map, "c1"));
  ASSERT_TRUE(ctl.SetRoute(f, Route(*map, {"c1", "c2", "c3"})).ok());
  EXPECT_EQ(ctl.Request(f, 0.0), TrafficDecision::kWait);
  EXPECT_EQ(ctl.HolderOf(P(*map, "c2")), static_cast<int>(w));
  EXPECT_EQ(ctl.HolderOf(P(*map, "c0")), -1);
  EXPECT_EQ(ctl.WaitsOn(f), static_cast<int>(w));
  EXPECT_EQ(ctl.WaitsOn(w), -1);
  EXPECT_EQ(ctl.ResolveDeadlocks(0.0), 0u);  // a chain that ends at a working robot
  ctl.WaitOn(w, static_cast<int>(f), 0.0, "waiting for its member");
  EXPECT_EQ(ctl.WaitsOn(w), static_cast<int>(f));
  EXPECT_EQ(ctl.ResolveDeadlocks(0.0), 1u);
  EXPECT_EQ(ctl.Request(f, 0.0), TrafficDecision::kGo);  // backing off to c0
  EXPECT_EQ(ctl.Next(f), P(*map, "c0"));
  EXPECT_EQ(ctl.At(w), P(*map, "c2"));
  ctl.WaitOn(w, -1, 1.0, {});
  EXPECT_EQ(ctl.WaitsOn(w), -1);
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

// A robot stopped inside an intersection before an exit that stays held backs off by the
// intersection's other exit when it closes a wait cycle (it holds the grant; backing off never
// enters an intersection otherwise). Found in the Chu2024 burst (Tables 1+2 x10, 0.5 s steps): a
// formation at X11-9 inside I5-4 waited for D-T5, where the team before it waited for a member
// whose way out led back through I5-4: 21 orders failed blocked, none with the back-off.
TEST(TrafficControllerTest, ARobotInsideAnIntersectionBacksOffByItsOtherExit) {
  MapBuilder b("loop");
  b.SetFloor({-1, -1}, {11, 11});
  b.AddRectZone("z", {-1, -1}, {11, 11});
  b.AddPoint("W", {2, 5}, PointKind::kLane);
  b.AddPoint("C1", {5, 5}, PointKind::kIntersection);
  b.AddPoint("C2", {6, 5}, PointKind::kIntersection);
  b.AddPoint("D", {5, 8}, PointKind::kLane);
  b.AddPoint("E", {9, 5}, PointKind::kLane);
  b.AddPoint("S", {5, 1}, PointKind::kLane);
  b.AddPath("W", "C1");
  b.AddPath("C1", "D");
  b.AddPath("D", "W");
  b.AddPath("C1", "C2");
  b.AddPath("C2", "E");
  b.AddPath("E", "S");
  b.AddPath("S", "W");
  b.AddIntersection("X", {"C1", "C2"}, {"W"});
  MapBuildOptions options;
  options.check_service_connectivity = false;
  auto built = b.Build(options);
  ASSERT_TRUE(built.ok()) << built.error().message;
  auto map = std::make_shared<const WarehouseMap>(std::move(built).value());
  TrafficController ctl = Make(map);
  const std::size_t h = *ctl.AddRobot("H", P(*map, "D"));  // works at D, waits on A
  ctl.SetWorking(h, true, 1e9);
  ctl.SetIdle(h, false);
  const std::size_t a = *ctl.AddRobot("A", P(*map, "C1"));  // inside X, holds its grant
  ASSERT_TRUE(ctl.SetRoute(a, Route(*map, {"C1", "D"})).ok());
  EXPECT_EQ(ctl.Request(a, 0.0), TrafficDecision::kWait);
  EXPECT_EQ(ctl.WaitsOn(a), static_cast<int>(h));
  ctl.WaitOn(h, static_cast<int>(a), 0.0, "waiting for a member A holds up");
  EXPECT_EQ(ctl.ResolveDeadlocks(0.0), 1u);
  EXPECT_EQ(ctl.Request(a, 0.0), TrafficDecision::kGo);
  EXPECT_EQ(ctl.Next(a), P(*map, "C2"));
  EXPECT_EQ(ctl.RemainingRoute(a), Route(*map, {"C1", "C2", "E", "S", "W", "C1", "D"}));
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
