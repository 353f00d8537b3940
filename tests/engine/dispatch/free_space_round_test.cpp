// Four-wheel-steer robots in the dispatch core (issue 17 §3): a round plans such a robot through
// the map's free-space regions by the hybrid A* (FleetState::UseFreeSpace), any other robot on
// the lanes; the order stream on the core runs both kinds to the end, safely.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "engine/dispatch/allocation_round.h"
#include "engine/dispatch/strategy.h"
#include "engine/map/map_builder.h"
#include "engine/routing/route_table.h"
#include "engine/sim/core_stream.h"

namespace dispatch::engine {
namespace {

// A bay (x 2-8 m, y 0.1-1.5 m: a free-space region) off a lane: P1 - w - E - m - K, the pick K
// near the bay's east end; the drop D and a second station P2 north of w.
// Dead end (loop = false): the bay is closed; a robot leaving K must turn round inside it: on
// the lanes it just drives back, a four-wheel-steer robot is planned a turn (a spin fits the
// 1.4 m bay, a car's turning circle does not).
// Loop (loop = true): one-way lanes w -> E -> m -> K -> X -> Y -> D -> w through the bay and
// back along the north, so two robots never meet head-on in it.
std::shared_ptr<const WarehouseMap> Bay(bool loop) {
  MapBuilder b(loop ? "bay-loop" : "bay");
  b.SetFloor({0, 0}, {10, 4});
  b.AddRectZone("z", {0, 0}, {10, 4});
  b.AddPoint("P1", {0.5, 0.8}, PointKind::kPark);
  b.AddPoint("w", {1.5, 0.8}, PointKind::kLane);
  b.AddPoint("E", {2.8, 0.8}, PointKind::kLane);
  b.AddPoint("m", {4.5, 0.8}, PointKind::kLane);
  b.AddPoint("K", {6.5, 0.8}, PointKind::kPick);
  b.AddPoint("D", {1.5, 2.8}, PointKind::kDrop);
  b.AddPoint("P2", {0.5, 2.8}, PointKind::kPark);
  b.AddPath("P1", "w", std::nullopt, 0.0, true);
  b.AddPath("D", "P2", std::nullopt, 0.0, true);
  if (loop) {
    b.AddPoint("X", {8.8, 0.8}, PointKind::kLane);
    b.AddPoint("Y", {8.8, 2.8}, PointKind::kLane);
    for (auto [from, to] : {std::pair{"w", "E"}, {"E", "m"}, {"m", "K"}, {"K", "X"}, {"X", "Y"}, {"Y", "D"}, {"D", "w"}}) {
      b.AddPath(from, to, std::nullopt, 0.0, false);
    }
  } else {
    for (auto [from, to] : {std::pair{"w", "E"}, {"E", "m"}, {"m", "K"}, {"w", "D"}}) {
      b.AddPath(from, to, std::nullopt, 0.0, true);
    }
  }
  b.AddStation("S1", "P1", 1);
  b.AddStation("S2", "P2", 1);
  b.AddFreeSpace("bay", {{2, 0.1}, {8, 0.1}, {8, 1.5}, {2, 1.5}});
  auto map = b.Build();
  if (!map.ok()) ADD_FAILURE() << map.error().message;
  return std::make_shared<const WarehouseMap>(std::move(map).value());
}

std::shared_ptr<const RouteTable> Routes(const std::shared_ptr<const WarehouseMap>& map) {
  auto routes = MakeRouteTable(map, {});
  if (!routes.ok()) ADD_FAILURE() << routes.error().message;
  return std::shared_ptr<const RouteTable>(std::move(routes).value());
}

std::shared_ptr<const Order> PickAtK(const WarehouseMap& map, const std::string& id, double t) {
  auto o = std::make_shared<Order>();
  o->id = id;
  o->picks = {*map.FindPoint("K")};
  o->drop = *map.FindPoint("D");
  o->created_time = t;
  return o;
}

TEST(FreeSpaceRound, AFourWheelSteerRobotIsPlannedThroughTheBayAnotherOnItsLanes) {
  const auto map = Bay(false);
  const auto routes = Routes(map);
  std::vector<Waypoint> plan_of[2];
  for (int steer = 0; steer < 2; ++steer) {
    RoundRunner runner(map, routes, AllocationConfig{}, std::move(MakeAllocator("auction")).value());
    RoundInput input;
    input.now = 0.0;
    RoundRobot r1;
    r1.id = "R1";
    r1.start = *map->FindPoint("P1");
    r1.kind = steer ? RobotKind::kFourWheelSteer : RobotKind::kDifferential;
    input.robots = {r1};
    input.pending = {PickAtK(*map, "o1", 0.0)};
    const RoundResult result = runner.Run(input);
    EXPECT_TRUE(result.notes.empty()) << result.notes.front();
    ASSERT_EQ(result.awards.size(), 1u);
    plan_of[steer] = result.awards[0].segments.at(0);
  }
  const std::vector<Waypoint>& lanes = plan_of[0];
  const std::vector<Waypoint>& steered = plan_of[1];
  for (const Waypoint& w : lanes) EXPECT_FALSE(w.mode.has_value() || w.heading.has_value());
  // The steered plan: the same stops, poses with modes inside the bay, and a turn there.
  std::set<MotionMode> modes;
  std::vector<WaypointAction> stops[2];
  for (int k = 0; k < 2; ++k) {
    for (const Waypoint& w : plan_of[k]) {
      if (w.action != WaypointAction::kMove) stops[k].push_back(w.action);
    }
  }
  for (const Waypoint& w : steered) {
    if (w.mode) {
      modes.insert(*w.mode);
      EXPECT_TRUE(map->free_spaces()[0].Contains(w.xy)) << w.xy.transpose();
    }
  }
  EXPECT_EQ(stops[0], stops[1]);
  EXPECT_GT(steered.size(), lanes.size());
  EXPECT_TRUE(modes.count(MotionMode::kSpinLeft) || modes.count(MotionMode::kSpinRight) ||
              modes.count(MotionMode::kReverse))
      << "no turn in the bay";
  EXPECT_EQ(steered.back().point, lanes.back().point);
  EXPECT_GE(steered.back().eta, lanes.back().eta);  // a turn takes time the lanes do not count
}

// A round over R1 (differential, at P1: the nearer) and R2 (four-wheel steer, at P2) with one
// order picking at K, `heading` asked for there if given.
RoundResult RoundWithBothKinds(std::optional<double> heading, bool steer_too = true) {
  const auto map = Bay(false);
  RoundRunner runner(map, Routes(map), AllocationConfig{}, std::move(MakeAllocator("auction")).value());
  RoundInput input;
  RoundRobot r1, r2;
  r1.id = "R1";
  r1.start = *map->FindPoint("P1");
  r2.id = "R2";
  r2.start = *map->FindPoint("P2");
  r2.kind = steer_too ? RobotKind::kFourWheelSteer : RobotKind::kDifferential;
  input.robots = {r1, r2};
  auto order = std::const_pointer_cast<Order>(PickAtK(*map, "o1", 0.0));
  if (heading) order->stop_headings[0] = *heading;
  input.pending = {order};
  return runner.Run(input);
}

// Issue 17 §3, "tasks have a position and a heading": the pick at K asks to be reached facing
// the bay's mouth (pi, the lanes arrive facing east). Only the four-wheel-steer robot can be
// planned into that pose, so it wins though the differential one is nearer (and does win
// without the heading); its pick waypoint holds the heading asked for.
TEST(FreeSpaceRound, AStopHeadingGoesToTheFourWheelSteerRobotPlannedIntoThatPose) {
  const RoundResult plain = RoundWithBothKinds(std::nullopt);
  ASSERT_EQ(plain.awards.size(), 1u);
  EXPECT_EQ(plain.awards[0].award.winners, std::vector<std::string>{"R1"});

  const double pi = std::numbers::pi;
  const RoundResult posed = RoundWithBothKinds(pi);
  EXPECT_TRUE(posed.notes.empty()) << posed.notes.front();
  ASSERT_EQ(posed.awards.size(), 1u);
  EXPECT_EQ(posed.awards[0].award.winners, std::vector<std::string>{"R2"});
  const auto& bids = posed.awards[0].award.bids;
  ASSERT_EQ(bids.size(), 2u);
  EXPECT_FALSE(bids[0].reachable) << "R1 cannot be planned into the heading and does not bid";
  int picks = 0;
  for (const Waypoint& w : posed.awards[0].segments.at(0)) {
    if (w.action != WaypointAction::kPick) continue;
    ++picks;
    ASSERT_TRUE(w.heading.has_value());
    EXPECT_NEAR(std::abs(*w.heading), pi, 1e-6);
  }
  EXPECT_EQ(picks, 1);
}

// No robot can be planned into the heading: the order is not allocated, and the round says why.
TEST(FreeSpaceRound, AStopHeadingNoRobotCanTakeLeavesTheOrderAcceptedSayingWhy) {
  const RoundResult r = RoundWithBothKinds(std::numbers::pi / 2, /*steer_too=*/false);
  EXPECT_TRUE(r.awards.empty());
  ASSERT_EQ(r.notes.size(), 1u);
  EXPECT_NE(r.notes[0].find("asks for a heading"), std::string::npos) << r.notes[0];
}

// One round on the dead-end bay: R1 at P1 (four-wheel steer when `steer`), R2 at P2 (a
// differential drive), `orders` pending, allocated by `strategy` under `config`.
RoundResult BayRound(const std::shared_ptr<const WarehouseMap>& map, const std::shared_ptr<const RouteTable>& routes,
                     const std::string& strategy, const AllocationConfig& config, bool steer,
                     std::vector<std::shared_ptr<const Order>> orders) {
  RoundRunner runner(map, routes, config, std::move(MakeAllocator(strategy)).value());
  RoundInput input;
  RoundRobot r1, r2;
  r1.id = "R1";
  r1.start = *map->FindPoint("P1");
  r1.kind = steer ? RobotKind::kFourWheelSteer : RobotKind::kDifferential;
  r2.id = "R2";
  r2.start = *map->FindPoint("P2");
  input.robots = {r1, r2};
  input.pending = std::move(orders);
  return runner.Run(input);
}

// The auction prices the legs a four-wheel-steer robot will drive: by the lanes R1 (4WIS, at
// P1) is 2 m nearer K than R2 (differential, at P2), but turning round in the dead-end bay
// costs it more than that (a spin of pi at 1 rad/s, where the lanes just drive back), so R2
// wins; R1's bid is its refined plan's time, which is more than its lanes' time.
TEST(FreeSpaceRound, TheBidsPriceTheRefinedLegs) {
  const auto map = Bay(false);
  const auto routes = Routes(map);
  const RoundResult result = BayRound(map, routes, "auction", AllocationConfig{}, true, {PickAtK(*map, "o1", 0.0)});
  ASSERT_EQ(result.awards.size(), 1u);
  EXPECT_EQ(result.awards[0].award.winners, std::vector<std::string>{"R2"}) << result.awards[0].award.reason;
  const PointId p1 = *map->FindPoint("P1");
  const Bid& steer = result.awards[0].award.bids.at(0);
  const Bid& lanes = result.awards[0].award.bids.at(1);
  const double k = *map->FindPoint("K"), d = *map->FindPoint("D");
  const double lanes_r1 = routes->Cost(p1, static_cast<PointId>(k)) +
                          routes->Cost(static_cast<PointId>(k), static_cast<PointId>(d));
  EXPECT_GT(steer.t_d, lanes_r1 + 2.0) << "R1's bid prices its turn in the bay";
  EXPECT_LT(lanes_r1, lanes.t_d) << "by the lanes alone R1 is nearer";
}

// The exact assignment and the greedy rule price the refined legs too (the lanes alone would
// send R1, 2 m nearer K): with one order the exact strategy's cost is R2's, the greedy rule's
// distance R1's refined drive to K.
TEST(FreeSpaceRound, TheOtherStrategiesPriceTheRefinedLegsToo) {
  const auto map = Bay(false);
  const auto routes = Routes(map);
  for (bool steer : {true, false}) {
    for (const char* strategy : {"exact", "greedy"}) {
      SCOPED_TRACE(std::string(strategy) + (steer ? ", R1 four-wheel steer" : ", R1 differential"));
      const RoundResult result = BayRound(map, routes, strategy, AllocationConfig{}, steer, {PickAtK(*map, "o1", 0.0)});
      ASSERT_EQ(result.awards.size(), 1u);
      // Without the four-wheel-steer kind the same round goes to R1, the nearer by the lanes.
      EXPECT_EQ(result.awards[0].award.winners, std::vector<std::string>{steer ? "R2" : "R1"})
          << result.awards[0].award.reason;
    }
  }
}

// Issue 17 under the planned planners: the time windows re-plan a round's awards on the graph,
// which knows no free space, so R1's refined segment (the order asks for heading pi at K)
// keeps its poses and its turn and is reserved as it is; R2, given a plain order at K in the
// same round, is planned to reach K only once R1 has left it (before, these planners did not
// refine at all: nobody could serve the heading).
TEST(FreeSpaceRound, ThePlannedPlannersKeepTheRefinedSegmentAndPlanRoundIt) {
  const auto map = Bay(false);
  const auto routes = Routes(map);
  const PointId k = *map->FindPoint("K");
  for (PlannerKind planner : {PlannerKind::kTimeWindows, PlannerKind::kConflictElimination}) {
    SCOPED_TRACE(PlannerName(planner));
    AllocationConfig config;
    config.planner = planner;
    auto posed = std::const_pointer_cast<Order>(PickAtK(*map, "o1", 0.0));
    posed->stop_headings[0] = std::numbers::pi;
    // Dropped where R1 started (P1), away from R2's drop (D).
    posed->drop = *map->FindPoint("P1");
    const RoundResult result = BayRound(map, routes, "auction", config, true, {posed, PickAtK(*map, "o2", 0.0)});
    EXPECT_TRUE(result.notes.empty()) << result.notes.front();
    ASSERT_EQ(result.awards.size(), 2u);
    ASSERT_EQ(result.awards[0].award.winners, std::vector<std::string>{"R1"}) << result.awards[0].award.reason;
    ASSERT_EQ(result.awards[1].award.winners, std::vector<std::string>{"R2"}) << result.awards[1].award.reason;
    const std::vector<Waypoint>& steered = result.awards[0].segments.at(0);
    std::set<MotionMode> modes;
    double r1_leaves_k = 0.0;
    for (const Waypoint& w : steered) {
      if (w.mode) modes.insert(*w.mode);
      if (w.point == k) r1_leaves_k = std::max(r1_leaves_k, w.departure());
      if (w.action == WaypointAction::kPick) {
        ASSERT_TRUE(w.heading.has_value());
        EXPECT_NEAR(std::abs(*w.heading), std::numbers::pi, 1e-6);
      }
    }
    EXPECT_TRUE(modes.count(MotionMode::kSpinLeft) || modes.count(MotionMode::kSpinRight) ||
                modes.count(MotionMode::kReverse))
        << "no turn in the bay";
    int picks = 0;
    for (const Waypoint& w : result.awards[1].segments.at(0)) {
      if (w.action != WaypointAction::kPick) continue;
      ++picks;
      EXPECT_FALSE(w.heading.has_value());
      EXPECT_GE(w.eta, r1_leaves_k) << "R2 reaches K while R1 is still there";
    }
    EXPECT_EQ(picks, 1);
  }
}

// Orders at K every 5 s through the core, checked for safety at every step.
Result<StreamResult> Serve(std::shared_ptr<const WarehouseMap> map, const std::vector<FleetRobot>& robots, int count,
                           PlannerKind planner = PlannerKind::kRules) {
  std::vector<Order> orders;
  for (int k = 0; k < count; ++k) {
    Order o = *PickAtK(*map, "o" + std::to_string(k + 1), 5.0 * k);
    o.release_time = 5.0 * k;
    orders.push_back(o);
  }
  StreamConfig config;
  config.check_safety = true;
  config.max_time = 600.0;
  config.allocation.planner = planner;
  config.traffic.execution = DefaultPlanExecution(planner);  // as dispatchd and dispatch-sim drive it
  return SimulateOnCore(map, Routes(map), robots, orders, config);
}

void ExpectAllDoneSafely(const Result<StreamResult>& run) {
  ASSERT_TRUE(run.ok()) << run.error().message;
  for (const auto& o : run->orders) EXPECT_TRUE(o.completed) << o.order_id << ": " << o.failure;
  ASSERT_TRUE(run->safety.has_value());
  EXPECT_TRUE(run->safety->ok()) << run->safety->violations.front().Describe();
}

TEST(FreeSpaceRound, AFourWheelSteerRobotTurnsRoundInTheDeadEndOrderAfterOrder) {
  const auto map = Bay(false);
  ExpectAllDoneSafely(Serve(map, {{"R1", *map->FindPoint("P1"), 0.0, RobotKind::kFourWheelSteer}}, 3));
}

// A free-space region holds one robot at a time (TrafficController::RegionBlocker): in the
// dead-end bay the two kinds take turns, order after order, and the safety check over the
// robots' true positions finds nothing. Without it the second robot drove in while the first
// turned round at K (and two robots in one dead end lock each other up).
// R1 (four-wheel steer, at P1) and R2 (differential, at P2) serve `count` orders at K on the
// core: every one completes safely, and both kinds serve the bay.
void ExpectBothKindsServe(bool loop, int count, PlannerKind planner = PlannerKind::kRules) {
  const auto map = Bay(loop);
  auto run = Serve(map,
                   {{"R1", *map->FindPoint("P1"), 0.0, RobotKind::kFourWheelSteer},
                    {"R2", *map->FindPoint("P2"), 0.0, RobotKind::kDifferential}},
                   count, planner);
  ExpectAllDoneSafely(run);
  if (!run.ok()) return;
  std::set<std::string> served;
  for (const auto& o : run->orders) served.insert(o.robot);
  EXPECT_EQ(served, (std::set<std::string>{"R1", "R2"})) << "both kinds served the bay";
}

TEST(FreeSpaceRound, BothKindsTakeTurnsInADeadEndBay) { ExpectBothKindsServe(false, 4); }

TEST(FreeSpaceRound, BothKindsServeTheBayOnTheCoreSafely) { ExpectBothKindsServe(true, 6); }

// The same under the time windows: the refined robot's windows keep the other one out of its
// way, and the traffic controller's one-robot-per-region rule stays the safety net.
TEST(FreeSpaceRound, TheTimeWindowsServeTheBayOnTheCore) {
  ExpectBothKindsServe(false, 4, PlannerKind::kTimeWindows);
  ExpectBothKindsServe(true, 6, PlannerKind::kTimeWindows);
}

}  // namespace
}  // namespace dispatch::engine
