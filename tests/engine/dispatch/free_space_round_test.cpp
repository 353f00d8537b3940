// Four-wheel-steer robots in the dispatch core (issue 17 §3): a round plans such a robot through
// the map's free-space regions by the hybrid A* (FleetState::UseFreeSpace), any other robot on
// the lanes; the order stream on the core runs both kinds to the end, safely.
#include <gtest/gtest.h>

#include <memory>
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

// Orders at K every 5 s through the core, checked for safety at every step.
Result<StreamResult> Serve(std::shared_ptr<const WarehouseMap> map, const std::vector<FleetRobot>& robots, int count) {
  std::vector<Order> orders;
  for (int k = 0; k < count; ++k) {
    Order o = *PickAtK(*map, "o" + std::to_string(k + 1), 5.0 * k);
    o.release_time = 5.0 * k;
    orders.push_back(o);
  }
  StreamConfig config;
  config.check_safety = true;
  config.max_time = 600.0;
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

TEST(FreeSpaceRound, BothKindsServeTheBayOnTheCoreSafely) {
  const auto map = Bay(true);
  auto run = Serve(map,
                   {{"R1", *map->FindPoint("P1"), 0.0, RobotKind::kFourWheelSteer},
                    {"R2", *map->FindPoint("P2"), 0.0, RobotKind::kDifferential}},
                   6);
  ExpectAllDoneSafely(run);
  std::set<std::string> served;
  for (const auto& o : run->orders) served.insert(o.robot);
  EXPECT_EQ(served, (std::set<std::string>{"R1", "R2"})) << "both kinds served the bay";
}

}  // namespace
}  // namespace dispatch::engine
