#include "engine/planning/path_heat.h"

#include <gtest/gtest.h>

#include "engine/routing/cost_graph.h"

#include "grid_map.h"

namespace dispatch::engine {
namespace {

using testing_grid::At;
using testing_grid::GridMap;

std::size_t LaneOf(const WarehouseMap& map, PointId a, PointId b) {
  return static_cast<std::size_t>(map.arc(*map.FindArc(a, b)).path);
}

// Seed 004 eqs. (13)-(14) on three lanes of a row: lane 0-1 used 3 times by 2 robots, lane
// 1-2 once by 1 robot, lane 2-3 not at all: Σ b·h = 2·3 + 1·1 = 7.
TEST(PathHeatTest, WeightsFollowEquationsThirteenAndFourteen) {
  const auto map = GridMap({"...."});
  const PointId p0 = At(*map, 0, 0), p1 = At(*map, 0, 1), p2 = At(*map, 0, 2), p3 = At(*map, 0, 3);
  const ArcId a01 = *map->FindArc(p0, p1), a10 = *map->FindArc(p1, p0), a12 = *map->FindArc(p1, p2);
  const std::vector<LaneUse> uses = {{a01, 1, 5.0}, {a10, 1, 9.0}, {a01, 2, 12.0}, {a12, 3, 20.0},
                                     {a12, 4, 100.0} /* after the period */, {-1, 5, 10.0} /* no arc */};
  const PathHeat heat = PathHeat::FromUses(*map, uses, 0.0, 60.0);
  const std::size_t l01 = LaneOf(*map, p0, p1), l12 = LaneOf(*map, p1, p2), l23 = LaneOf(*map, p2, p3);
  EXPECT_EQ(heat.Heat(l01), 3);
  EXPECT_EQ(heat.Robots(l01), 2);
  EXPECT_EQ(heat.Heat(l12), 1);
  EXPECT_EQ(heat.Robots(l12), 1);
  EXPECT_DOUBLE_EQ(heat.Weight(l01), 1.0 + 3.0 * 3.0 / 7.0);  // (b + 1) h / Σ = 9 / 7
  EXPECT_DOUBLE_EQ(heat.Weight(l12), 1.0 + 2.0 * 1.0 / 7.0);
  EXPECT_DOUBLE_EQ(heat.Weight(l23), 1.0);
  EXPECT_DOUBLE_EQ(heat.ArcWeight(*map, a10), heat.Weight(l01));  // both directions: one lane
  const PathHeat cold = PathHeat::FromUses(*map, {}, 0.0, 60.0);
  EXPECT_DOUBLE_EQ(cold.Weight(l01), 1.0);
}

// Step 5: between two routes of one length the weighted Dijkstra takes the cold one, whichever
// side is hot; a hot lane's weight is its share of the use (eq. (13)), so it does not send a
// robot twice as far.
TEST(PathHeatTest, RoutesTakeTheColderOfEqualRoutes) {
  const auto map = GridMap({"...", "...", "..."});
  const PointId from = At(*map, 0, 0), to = At(*map, 1, 1);
  auto busy = [&](PointId a, PointId b) {
    std::vector<LaneUse> uses;
    for (int robot = 0; robot < 3; ++robot) uses.push_back({*map->FindArc(a, b), robot, 1.0 + robot});
    return PathHeat::FromUses(*map, uses, 0.0, 60.0);
  };
  auto via = [&](const PathHeat& heat, PointId p) {
    auto r = HeatRoute(*map, heat, from, to, 1.0);
    EXPECT_TRUE(r.ok());
    EXPECT_DOUBLE_EQ(r->length, 2.0);
    EXPECT_DOUBLE_EQ(r->cost, 2.0);  // drive time: metres at 1 m/s, not the weights
    return std::count(r->points.begin(), r->points.end(), p) == 1;
  };
  EXPECT_TRUE(via(busy(At(*map, 0, 0), At(*map, 0, 1)), At(*map, 1, 0)));  // east hot: south first
  EXPECT_TRUE(via(busy(At(*map, 0, 0), At(*map, 1, 0)), At(*map, 0, 1)));  // south hot: east first
  // Far round a hot lane it does not go: weight 1 + (3 + 1) * 3 / 9 < 3.
  const PathHeat hot = busy(At(*map, 0, 0), At(*map, 0, 1));
  auto straight = HeatRoute(*map, hot, At(*map, 0, 0), At(*map, 0, 1), 1.0);
  ASSERT_TRUE(straight.ok());
  EXPECT_DOUBLE_EQ(straight->length, 1.0);
  EXPECT_EQ(HeatRoute(*map, hot, from, 99, 1.0).error().code, ErrorCode::kNotFound);
  const auto split = GridMap({".@."});
  EXPECT_EQ(HeatRoute(*split, PathHeat::FromUses(*split, {}, 0, 1), At(*split, 0, 0), At(*split, 0, 2), 1.0).error().code,
            ErrorCode::kUnreachable);
}

// The seed's improved Dijkstra (§4.1) weighs turning time too (eq. (3), t_c per 90 degrees):
// across an open 4 x 4 grid every shortest route is 6 m, and with 1 s per turn the route
// turns once; a robot that arrived heading east goes on east before it turns.
TEST(PathHeatTest, TurningTimeMakesRoutesTurnOnce) {
  const auto map = GridMap({"....", "....", "....", "...."});
  const PathHeat cold = PathHeat::FromUses(*map, {}, 0.0, 60.0);
  auto turns = [&](const Route& r) {
    int n = 0;
    for (std::size_t k = 1; k < r.arcs.size(); ++k) n += TurnAngle(*map, r.arcs[k - 1], r.arcs[k]) > 0.1 ? 1 : 0;
    return n;
  };
  auto r = HeatRoute(*map, cold, At(*map, 0, 0), At(*map, 3, 3), 1.0, 1.0);
  ASSERT_TRUE(r.ok());
  EXPECT_DOUBLE_EQ(r->length, 6.0);
  EXPECT_EQ(turns(*r), 1);
  EXPECT_DOUBLE_EQ(r->cost, 7.0);  // 6 s driving + one 90-degree turn
  const ArcId east = *map->FindArc(At(*map, 0, 0), At(*map, 0, 1));
  auto headed = HeatRoute(*map, cold, At(*map, 0, 1), At(*map, 3, 3), 1.0, 1.0, east);
  ASSERT_TRUE(headed.ok());
  EXPECT_EQ(headed->points[1], At(*map, 0, 2));  // on east first: turning at the start costs the same
  EXPECT_EQ(turns(*headed), 1);
  EXPECT_DOUBLE_EQ(headed->cost, 6.0);
  // A U-turn counts twice: back to where it came from takes 2 s of turning and 1 s driving.
  auto back = HeatRoute(*map, cold, At(*map, 0, 1), At(*map, 0, 0), 1.0, 1.0, east);
  ASSERT_TRUE(back.ok());
  EXPECT_DOUBLE_EQ(back->cost, 3.0);
  // Heat against turning: the lane east of the start is hot (weight 1 + 4 * 3 / 10 = 2.2). To
  // the cell south-east, a robot heading east goes south first (2 m, two turns) when turns
  // are free, and through the hot lane (one turn) when a turn takes 5 s.
  std::vector<LaneUse> uses;
  for (int robot = 0; robot < 3; ++robot) uses.push_back({*map->FindArc(At(*map, 0, 1), At(*map, 0, 2)), robot, 1.0});
  uses.push_back({*map->FindArc(At(*map, 2, 0), At(*map, 3, 0)), 9, 1.0});
  const PathHeat hot = PathHeat::FromUses(*map, uses, 0.0, 60.0);
  auto free_turns = HeatRoute(*map, hot, At(*map, 0, 1), At(*map, 1, 2), 1.0, 0.0, east);
  ASSERT_TRUE(free_turns.ok());
  EXPECT_EQ(free_turns->points[1], At(*map, 1, 1));
  auto slow_turns = HeatRoute(*map, hot, At(*map, 0, 1), At(*map, 1, 2), 1.0, 5.0, east);
  ASSERT_TRUE(slow_turns.ok());
  EXPECT_EQ(slow_turns->points[1], At(*map, 0, 2));
  EXPECT_DOUBLE_EQ(slow_turns->cost, 7.0);  // unweighted: 2 s driving + 5 s turning
}

// The table form (the auction's costs under routing = heat): the cold one of two equal
// routes, costed at its drive time; HeatRoute's routes wherever the heat sends them.
TEST(PathHeatTest, TheHeatTableRoutesAsHeatRouteAndCostsTheDriveTime) {
  const auto map = GridMap({"....", ".@..", "....", "..@."});
  std::vector<LaneUse> uses;
  for (int robot = 0; robot < 3; ++robot) {
    uses.push_back({*map->FindArc(At(*map, 0, 0), At(*map, 0, 1)), robot, 1.0 + robot});
    uses.push_back({*map->FindArc(At(*map, 3, 0), At(*map, 3, 1)), robot, 2.0});
  }
  const PathHeat heat = PathHeat::FromUses(*map, uses, 0.0, 60.0);
  RouteTableOptions options;
  const auto table = HeatRouteTable(map, heat, options).value();
  EXPECT_EQ(table->method(), "weighted");
  const auto south_first = table->Path(At(*map, 0, 0), At(*map, 2, 2)).value();
  EXPECT_EQ(south_first.points[1], At(*map, 1, 0));
  EXPECT_DOUBLE_EQ(table->Cost(At(*map, 0, 0), At(*map, 2, 2)), 4.0);
  // Every pair: the weighted length of the table's route is HeatRoute's (the same optimum).
  auto weighted = [&](const Route& r) {
    double sum = 0.0;
    for (ArcId a : r.arcs) sum += heat.ArcWeight(*map, a) * map->arc(a).length;
    return sum;
  };
  for (PointId u = 0; u < static_cast<PointId>(map->point_count()); ++u) {
    for (PointId v = 0; v < static_cast<PointId>(map->point_count()); ++v) {
      const auto expected = HeatRoute(*map, heat, u, v, 1.0);
      const auto got = table->Path(u, v);
      ASSERT_EQ(expected.ok(), got.ok()) << u << "->" << v;
      if (!got.ok()) continue;
      EXPECT_NEAR(weighted(*got), weighted(*expected), 1e-9) << u << "->" << v;
      EXPECT_DOUBLE_EQ(table->Cost(u, v), got->cost);
      EXPECT_DOUBLE_EQ(got->cost, got->length);  // 1 m/s, no turning time
    }
  }
}

}  // namespace
}  // namespace dispatch::engine
