#include "engine/planning/path_heat.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace dispatch::engine
