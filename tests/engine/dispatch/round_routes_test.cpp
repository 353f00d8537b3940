// A round's routes other than the route table's (issue 16 §3): the time-window planner and
// BIT2024's conflict elimination (window_awards.h), and Wang2019's path heat (heat_awards.h).
// Each gives the strategy's awards with their stops, only routed or timed again.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "engine/dispatch/heat_awards.h"
#include "engine/dispatch/strategy.h"
#include "engine/dispatch/window_awards.h"
#include "engine/map/map_builder.h"
#include "engine/planning/path_heat.h"
#include "engine/planning/time_windows.h"
#include "tests/engine/dispatch/dispatch_test_support.h"

namespace dispatch::engine {
namespace {

using testing_util::Chu2024;
using testing_util::Chu2024Routes;
using testing_util::MakeOrder;
using testing_util::StopsOfFloor;

RoundResult RunRound(const AllocationConfig& config, const RoundInput& input) {
  RoundRunner runner(Chu2024(), Chu2024Routes(), config, std::move(MakeAllocator("auction")).value());
  return runner.Run(input);
}

struct Stop {
  PointId point;
  WaypointAction action;
  double dwell;
  bool operator==(const Stop& o) const { return point == o.point && action == o.action && dwell == o.dwell; }
};

std::vector<Stop> StopsOf(const std::vector<Waypoint>& segment) {
  std::vector<Stop> out;
  for (const Waypoint& w : segment) {
    if (w.action == WaypointAction::kPick || w.action == WaypointAction::kDrop) out.push_back({w.point, w.action, w.dwell});
  }
  return out;
}

// 8 robots at parking stations, 10 orders with distinct drops.
RoundInput BusyRound() {
  const auto& map = *Chu2024();
  const auto [parks, picks, drops] = StopsOfFloor(map);
  RoundInput input;
  input.now = 50.0;
  for (int i = 0; i < 8; ++i) {
    input.robots.push_back({"R" + std::to_string(i + 1), parks.at(static_cast<std::size_t>(i) * 2), {}, 0, {}});
  }
  for (int k = 0; k < 10; ++k) {  // more orders than robots: some robots get a queue
    input.pending.push_back(MakeOrder("o" + std::to_string(k), picks.at(static_cast<std::size_t>(k * 7 % 96)),
                                      drops.at(static_cast<std::size_t>(k)), 1.0 + k));
  }
  return input;
}

enum class Mode { kHeat, kTimeWindows, kConflictElimination };

AllocationConfig ConfigOf(Mode mode) {
  AllocationConfig c;
  if (mode == Mode::kHeat) c.routing = RoutingKind::kHeat;
  if (mode == Mode::kTimeWindows) c.planner = PlannerKind::kTimeWindows;
  if (mode == Mode::kConflictElimination) c.planner = PlannerKind::kConflictElimination;
  return c;
}

class RoundRoutesTest : public ::testing::TestWithParam<Mode> {
 protected:
  AllocationConfig Config() const { return ConfigOf(GetParam()); }
};

// Each robot's new waypoints of the round as timed visits (a robot stays at its last stop),
// reserved together: the round's new routes, for EarliestConflict.
ReservationTable NewRoutes(const RoundResult& round) {
  ReservationTable table(Chu2024(), TimeWindowRules{});
  std::map<std::string, std::vector<Waypoint>> of;
  for (const RoundAward& a : round.awards) {
    if (a.award.winners.size() != 1) continue;
    auto& w = of[a.award.winners[0]];
    w.insert(w.end(), a.segments[0].begin(), a.segments[0].end());
  }
  int robot = 0;
  for (const auto& [id, w] : of) {
    TimedRoute r;
    for (const Waypoint& x : w) {
      if (!r.empty() && r.back().point == x.point) {
        r.back().depart = std::max(r.back().depart, x.departure());
        continue;
      }
      r.push_back({x.point, x.eta, x.departure()});
    }
    r.back().depart = kForever;
    EXPECT_TRUE(table.Reserve(robot++, r).ok()) << id;
  }
  return table;
}

TEST_P(RoundRoutesTest, SegmentsKeepTheirAwardsAndStopsAndFollowTheMapsArcs) {
  const auto& map = *Chu2024();
  const RoundInput input = BusyRound();
  const RoundResult table = RunRound(AllocationConfig{}, input);
  const RoundResult other = RunRound(Config(), input);
  EXPECT_TRUE(other.notes.empty()) << other.notes.front();
  ASSERT_EQ(table.awards.size(), other.awards.size());
  int changed = 0;
  for (std::size_t k = 0; k < table.awards.size(); ++k) {
    const RoundAward& a = table.awards[k];
    const RoundAward& b = other.awards[k];
    SCOPED_TRACE(b.order_id);
    EXPECT_EQ(a.order_id, b.order_id);
    EXPECT_EQ(a.award.winners, b.award.winners);
    ASSERT_EQ(b.segments.size(), 1u);
    EXPECT_EQ(StopsOf(a.segments[0]), StopsOf(b.segments[0]));
    const auto& seg = b.segments[0];
    for (std::size_t i = 1; i < seg.size(); ++i) {
      EXPECT_LE(seg[i - 1].departure(), seg[i].eta + 1e-9);
      if (seg[i].point == seg[i - 1].point) continue;
      const auto arc = map.FindArc(seg[i - 1].point, seg[i].point);
      ASSERT_TRUE(arc);
      if (GetParam() == Mode::kHeat) {  // heat: timed at 1 m/s along its route
        EXPECT_NEAR(seg[i].eta - seg[i - 1].departure(), map.arc(*arc).length, 1e-9);
      }
    }
    if (a.segments[0].size() != seg.size() || a.segments[0].back().eta != seg.back().eta) ++changed;
  }
  EXPECT_GT(changed, 0);  // some robot waits for, or goes round, the others
}

INSTANTIATE_TEST_SUITE_P(Planners, RoundRoutesTest,
                         ::testing::Values(Mode::kHeat, Mode::kTimeWindows, Mode::kConflictElimination),
                         [](const auto& info) {
                           return std::string(info.param == Mode::kHeat          ? "Heat"
                                              : info.param == Mode::kTimeWindows ? "TimeWindows"
                                                                                 : "ConflictElimination");
                         });

// The table's routes of the busy round conflict (two windows at a point, or a lane both ways
// at once); both planners through the time windows leave none among the round's new routes:
// the time-window planner by planning each robot through the routes planned before it, BIT2024
// step 7 by constraining one robot of each conflict at a time. The same input gives the same
// routes (the seeded choice comes from the round).
// A robot standing at the order's pick: the route's first visit is a stop. The segment keeps
// its pick there and its drop (found on a dense grid: such a segment came out with neither, so
// its order never finished nor failed, and the run waited until its limit).
TEST_P(RoundRoutesTest, AStopWhereTheRobotStandsKeepsItsWaypoint) {
  const auto& map = *Chu2024();
  const auto [parks, picks, drops] = StopsOfFloor(map);
  RoundInput input;
  input.now = 10.0;
  input.robots.push_back({"R1", picks.at(5), {}, 0, {}});
  input.pending.push_back(MakeOrder("o1", picks.at(5), drops.at(2), 1.0));
  const RoundResult table = RunRound(AllocationConfig{}, input);
  const RoundResult other = RunRound(Config(), input);
  ASSERT_EQ(table.awards.size(), 1u);
  ASSERT_EQ(other.awards.size(), 1u);
  EXPECT_TRUE(other.notes.empty()) << other.notes.front();
  const std::vector<Stop> stops = StopsOf(other.awards[0].segments.at(0));
  EXPECT_EQ(StopsOf(table.awards[0].segments.at(0)), stops);
  ASSERT_EQ(stops.size(), 2u);
  EXPECT_EQ(stops[0].point, picks.at(5));
  EXPECT_EQ(stops[0].action, WaypointAction::kPick);
  const auto& seg = other.awards[0].segments[0];
  for (std::size_t i = 1; i < seg.size(); ++i) EXPECT_LE(seg[i - 1].departure(), seg[i].eta + 1e-9);
}

// Two robots dropping at one drop in one round: the first one's plan holds the drop only a
// few seconds after its work (it steps aside then), so the second is planned through the
// windows too, reaching the drop after the first has left it. Held for ever, the drop was
// "never free long enough" and the second kept the strategy's route.
TEST(RoundRoutes, ASecondRobotDroppingWhereAnotherEndsIsPlannedToo) {
  const auto& map = *Chu2024();
  const auto [parks, picks, drops] = StopsOfFloor(map);
  RoundInput input;
  input.now = 10.0;
  input.robots.push_back({"R1", parks.at(0), {}, 0, {}});
  input.robots.push_back({"R2", parks.at(8), {}, 0, {}});
  input.pending.push_back(MakeOrder("o1", picks.at(3), drops.at(1), 1.0));
  input.pending.push_back(MakeOrder("o2", picks.at(40), drops.at(1), 2.0));
  for (Mode mode : {Mode::kTimeWindows, Mode::kConflictElimination}) {
    SCOPED_TRACE(mode == Mode::kTimeWindows ? "time windows" : "conflict elimination");
    const RoundResult other = RunRound(ConfigOf(mode), input);
    EXPECT_TRUE(other.notes.empty()) << other.notes.front();
    ASSERT_EQ(other.awards.size(), 2u);
    ASSERT_NE(other.awards[0].award.winners, other.awards[1].award.winners);
    double first_leaves = 0.0, second_arrives = 0.0;
    for (const Waypoint& w : other.awards[0].segments.at(0)) {
      if (w.action == WaypointAction::kDrop) first_leaves = w.departure();
    }
    for (const Waypoint& w : other.awards[1].segments.at(0)) {
      if (w.action == WaypointAction::kDrop) second_arrives = w.eta;
    }
    EXPECT_GT(first_leaves, 0.0);
    EXPECT_GE(second_arrives, first_leaves);
  }
}

TEST(RoundRoutes, PlannersInTheWindowsLeaveNoConflictAmongTheRoundsRoutes) {
  const RoundInput input = BusyRound();
  EXPECT_TRUE(EarliestConflict(NewRoutes(RunRound(AllocationConfig{}, input))).has_value());
  for (Mode mode : {Mode::kTimeWindows, Mode::kConflictElimination}) {
    const RoundResult round = RunRound(ConfigOf(mode), input);
    const auto conflict = EarliestConflict(NewRoutes(round));
    EXPECT_FALSE(conflict.has_value()) << "robots " << conflict->a.robot << " and " << conflict->b.robot << " at "
                                       << conflict->at;
    const RoundResult again = RunRound(ConfigOf(mode), input);
    ASSERT_EQ(round.awards.size(), again.awards.size());
    for (std::size_t k = 0; k < round.awards.size(); ++k) {
      ASSERT_EQ(round.awards[k].segments[0].size(), again.awards[k].segments[0].size());
      for (std::size_t i = 0; i < round.awards[k].segments[0].size(); ++i) {
        EXPECT_EQ(round.awards[k].segments[0][i].point, again.awards[k].segments[0][i].point);
        EXPECT_EQ(round.awards[k].segments[0][i].eta, again.awards[k].segments[0][i].eta);
      }
    }
  }
}

// Heat in the bids (issue 16 §1): under routing = heat a robot's bid prices the route it will
// drive, Wang2019's step 5 over the lanes the plans use in the next heat_period. A floor with
// two ways from S to T: the straight lanes S-M-T (2 m) and round by L (2.33 m). W's plan
// drives S -> T -> S, so both straight lanes are hot (h = 2, b = 1: w = 1 + 2 * 2 / 4 = 2) and
// the heat route from S to T goes round by L. B, idle at P beside S, bids for an order from T
// to D: its T_d is 1 + 2.33 + 1 s at 1 m/s under heat (HeatRoute's times, recomputed here),
// 4 s by the table's shortest routes.
TEST(RoundRoutes, UnderHeatRoutingTheBidsPriceTheHeatRoutes) {
  MapBuilder builder("two-ways");
  builder.SetFloor({-2.0, -2.0}, {4.0, 1.0});
  builder.AddRectZone("all", {-2.0, -2.0}, {4.0, 1.0});
  builder.AddPoint("P", {-1.0, 0.0}, PointKind::kPark);
  builder.AddPoint("S", {0.0, 0.0}, PointKind::kLane);
  builder.AddPoint("M", {1.0, 0.0}, PointKind::kLane);
  builder.AddPoint("L", {1.0, -0.6}, PointKind::kLane);
  builder.AddPoint("T", {2.0, 0.0}, PointKind::kPick);
  builder.AddPoint("D", {3.0, 0.0}, PointKind::kDrop);
  for (const auto& [a, b] : std::vector<std::pair<std::string, std::string>>{
           {"P", "S"}, {"S", "M"}, {"M", "T"}, {"S", "L"}, {"L", "T"}, {"T", "D"}}) {
    builder.AddPath(a, b, std::nullopt, 0.0, true);
  }
  const auto map = std::make_shared<const WarehouseMap>(builder.Build().value());
  auto at = [&](const char* name) { return *map->FindPoint(name); };
  const std::shared_ptr<const RouteTable> table = MakeRouteTable(map, RouteTableOptions{}).value();
  AllocationConfig config;
  config.routing = RoutingKind::kHeat;
  const std::vector<FleetRobot> robots = {{"B", at("P"), 0.0}, {"W", at("S"), 0.0}};
  auto fleet = [&] {
    FleetState f = FleetState::Create(map, table, robots, config).value();
    EXPECT_TRUE(f.AssignSingle(1, "w", f.TaskOf({at("T")}, at("S"), 5.0)).ok());
    return f;
  };
  FleetState plain = fleet(), hot = fleet();
  ASSERT_TRUE(UseHeatRoutes(map, config, hot, 0.0).ok());
  EXPECT_EQ(hot.routes().method(), "weighted");
  const auto order = MakeOrder("o", at("T"), at("D"), 0.0);
  const auto by_table = MakeAllocator("auction").value()->Allocate(*order, plain).value();
  const auto by_heat = MakeAllocator("auction").value()->Allocate(*order, hot).value();
  // The heat of W's plan, recomputed from its waypoints.
  std::vector<LaneUse> uses;
  const auto& w = plain.plan(1).waypoints;
  for (std::size_t k = 1; k < w.size(); ++k) {
    if (const auto a = map->FindArc(w[k - 1].point, w[k].point)) uses.push_back({*a, 1, w[k - 1].departure()});
  }
  const PathHeat heat = PathHeat::FromUses(*map, uses, 0.0, config.heat_period);
  EXPECT_DOUBLE_EQ(heat.ArcWeight(*map, *map->FindArc(at("S"), at("M"))), 2.0);
  const double round_by_l = 2.0 * std::hypot(1.0, 0.6);
  EXPECT_NEAR(by_table.bids.at(0).t_d, 4.0, 1e-9);
  EXPECT_NEAR(by_heat.bids.at(0).t_d, 2.0 + round_by_l, 1e-9);
  EXPECT_NEAR(by_heat.bids.at(0).t_d,
              HeatRoute(*map, heat, at("P"), at("T"), 1.0)->cost + HeatRoute(*map, heat, at("T"), at("D"), 1.0)->cost,
              1e-9);
  EXPECT_GE(by_heat.bids.at(1).t_d, by_table.bids.at(1).t_d - 1e-9);
  // B's plan for the order goes round by L.
  const auto& b = hot.plan(0).waypoints;
  EXPECT_TRUE(std::any_of(b.begin(), b.end(), [&](const Waypoint& x) { return x.point == at("L"); }));
  // Nothing planned: no lane is hot, the fleet keeps its table.
  FleetState idle = FleetState::Create(map, table, robots, config).value();
  ASSERT_TRUE(UseHeatRoutes(map, config, idle, 0.0).ok());
  EXPECT_EQ(idle.routes().method(), table->method());
}

TEST(RoundRoutes, NamesRoundTripAndBadSettingsAreRefused) {
  for (const std::string& name : PlannerNames()) EXPECT_EQ(PlannerName(*ParsePlanner(name)), name);
  for (const std::string& name : RoutingNames()) EXPECT_EQ(RoutingName(*ParseRouting(name)), name);
  EXPECT_EQ(ParsePlanner("conflict-elimination"), PlannerKind::kConflictElimination);
  EXPECT_FALSE(ParsePlanner("cbs"));
  EXPECT_FALSE(ParseRouting("astar"));
  AllocationConfig bad;
  bad.windows.body_length = 0.0;
  EXPECT_FALSE(ValidateAllocationConfig(bad).ok());
  bad = {};
  bad.heat_period = 0.0;
  EXPECT_FALSE(ValidateAllocationConfig(bad).ok());
}

}  // namespace
}  // namespace dispatch::engine
