// TrafficController: breaking wait-for cycles (detours, back-offs, priority), Wang2019's case
// ② (a waiting robot of lower priority gives way), nudging idle robots aside and blocked
// robots, driven like the simulator drives it (positions and time only).
#include "engine/traffic/traffic_controller.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
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

// A robot inside a corridor that the robot it waits for must enter does not back off inside
// that corridor when its way on leads back through where it stood: it would still hold the
// corridor the other way, and come straight back. X (lower priority) drives east down the
// bottom corridor c16-c18 to the stub c20; Y stands at the junction c19, bound west down the
// same corridor to c14. X has no way but through c19; Y has one round the top. Before, X backed
// off to c17 and returned, again and again, while Y waited on it (found on a dense grid with
// the time-window planner, until both were blocked); now Y goes round and both arrive.
TEST(TrafficControllerTest, ABackOffInsideTheCorridorTheOtherNeedsIsNotTaken) {
  auto map = Grid({"@.....@", "@.@@@.@", "......."});
  TrafficController ctl = Make(map);
  const std::size_t y = *ctl.AddRobot("Y", P(*map, "c19"));
  const std::size_t x = *ctl.AddRobot("X", P(*map, "c18"));
  ASSERT_TRUE(ctl.SetRoute(y, Route(*map, {"c19", "c18", "c17", "c16", "c15", "c14"})).ok());
  ASSERT_TRUE(ctl.SetRoute(x, Route(*map, {"c18", "c19", "c20"})).ok());
  double t = 0.0;
  bool x_backed = false;
  for (int i = 0; i < 40 && (ctl.At(x) != P(*map, "c20") || ctl.At(y) != P(*map, "c14")); ++i) {
    Step(ctl, t += 1.0);
    x_backed = x_backed || ctl.At(x) == P(*map, "c17") || ctl.Next(x) == P(*map, "c17");
  }
  EXPECT_FALSE(x_backed);
  EXPECT_EQ(ctl.At(x), P(*map, "c20"));
  EXPECT_EQ(ctl.At(y), P(*map, "c14"));
  EXPECT_GE(ctl.stats().deadlocks_resolved, 1u);
}

// A detour keeps going round the point its robot last went round while the robot there holds
// it: a later head-on's detour does not lead back to it. R, bound for c15, waits at c13 for
// c14, where H works; after T_w2 it goes round by the top. Coming to the right-hand corridor
// (c2 ... c16) it meets O driving the other way in it; the way round that corridor, c2-c8-c14,
// is far shorter than the way on, but runs through c14 again, where H still works: R waits for
// O instead. Before, it took it and came back to wait at c14 (found on a dense grid: round and
// back every 8 s until it was blocked).
TEST(TrafficControllerTest, AHeadOnDetourDoesNotLeadBackToThePointWentRound) {
  auto map = Grid({"......", ".@.@@.", "......", "@@@@.@"});
  TrafficController ctl = Make(map);
  const std::size_t h = *ctl.AddRobot("H", P(*map, "c14"));
  ctl.SetWorking(h, true, 1e9);
  ctl.SetIdle(h, false);
  const std::size_t r = *ctl.AddRobot("R", P(*map, "c12"));
  const std::size_t o = *ctl.AddRobot("O", P(*map, "c22"));
  ASSERT_TRUE(ctl.SetRoute(r, Route(*map, {"c12", "c13", "c14", "c15"})).ok());
  double t = 0.0;
  bool went_round = false;
  for (int i = 0; i < 60 && ctl.stats().head_on.empty(); ++i) {
    Step(ctl, t += 1.0);
    if (!went_round && ctl.RemainingRoute(r).size() > 4) {  // gone round by the top: O sets off
      went_round = true;
      ASSERT_TRUE(ctl.SetRoute(o, Route(*map, {"c22", "c16", "c17", "c11", "c5", "c4", "c3", "c2", "c8"})).ok());
    }
  }
  ASSERT_TRUE(went_round);
  ASSERT_FALSE(ctl.stats().head_on.empty());
  const HeadOnRecord& met = ctl.stats().head_on.front();
  EXPECT_EQ(met.robot, "R");
  EXPECT_EQ(met.oncoming, "O");
  EXPECT_FALSE(met.replanned) << "wait " << met.wait_estimate << " s, detour +" << met.replan_extra << " s";
  const auto route = ctl.RemainingRoute(r);
  EXPECT_EQ(std::find(route.begin(), route.end(), P(*map, "c14")), route.end());
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

}  // namespace
}  // namespace dispatch::engine
