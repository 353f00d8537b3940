#include "engine/planning/time_windows.h"

#include <gtest/gtest.h>

#include "grid_map.h"

namespace dispatch::engine {
namespace {

using testing_grid::At;
using testing_grid::GridMap;

class TimeWindowsTest : public ::testing::Test {
 protected:
  std::shared_ptr<const WarehouseMap> map = GridMap({"...."});  // r0c0 .. r0c3, 1 m apart
  PointId p0 = At(*map, 0, 0), p1 = At(*map, 0, 1), p2 = At(*map, 0, 2), p3 = At(*map, 0, 3);
};

TEST_F(TimeWindowsTest, AReservedRouteHoldsItsPointsUntilClearAndItsLanes) {
  TimeWindowRules rules;  // 1 m/s, body 0.5 m, headway 0.5 s: clear 1 s
  ReservationTable table(map, rules);
  ASSERT_TRUE(table.Reserve(7, {{p0, 0, 0}, {p1, 1, 3}, {p2, 4, kForever}}).ok());
  ASSERT_EQ(table.PointWindows(p1).size(), 1u);
  EXPECT_DOUBLE_EQ(table.PointWindows(p1)[0].from, 1.0);
  EXPECT_DOUBLE_EQ(table.PointWindows(p1)[0].to, 4.0);  // left at 3, clear 1 s later
  const auto free = table.FreeIntervals(p1, 8);
  ASSERT_EQ(free.size(), 2u);
  EXPECT_DOUBLE_EQ(free[0].second, 1.0);
  EXPECT_DOUBLE_EQ(free[1].first, 4.0);
  EXPECT_EQ(table.FreeIntervals(p1, 7).size(), 1u);  // its own windows do not count
  EXPECT_TRUE(std::isinf(table.PointWindows(p2)[0].to));
  EXPECT_EQ(table.SameDirectionDuring(*map->FindArc(p1, p2), 3.5, 3.6, 8), 1);
  // The other direction of the lane p1-p2 is held while 7 drives it: from 4 on it is free.
  EXPECT_DOUBLE_EQ(table.OppositeFreeFrom(*map->FindArc(p2, p1), 2.5, 1.0, 8), 4.0);
  table.Release(7);
  EXPECT_TRUE(table.PointWindows(p1).empty());
  EXPECT_EQ(table.RouteOf(7), nullptr);
}

TEST_F(TimeWindowsTest, MalformedRoutesAreRefusedWithTheirFault) {
  ReservationTable table(map, {});
  auto fault = [&](const TimedRoute& r) { return table.Reserve(1, r).error().message; };
  EXPECT_NE(fault({{p0, 0, 0}, {p2, 1, 1}}).find("no arc"), std::string::npos);
  EXPECT_NE(fault({{p0, 0, 0}, {p1, 0.5, 1}}).find("faster than the arc allows"), std::string::npos);
  EXPECT_NE(fault({{p0, 2, 1}}).find("before it arrives"), std::string::npos);
  EXPECT_NE(fault({{p0, 0, kForever}, {p1, 1, 1}}).find("not the last"), std::string::npos);
  EXPECT_NE(fault({{99, 0, 0}}).find("not on the map"), std::string::npos);
}

TEST_F(TimeWindowsTest, TheCheckerFindsTwoRobotsAtOnePoint) {
  const TimeWindowRules rules;
  EXPECT_TRUE(CheckTimeWindows(*map, rules, {{{p0, 0, 0}, {p1, 1, kForever}}, {{p3, 0, 2}, {p2, 3, kForever}}}).ok());
  // The second arrives at r0c1 0.5 s after the first left it (clear takes 1 s).
  const auto close = CheckTimeWindows(*map, rules, {{{p1, 0, 1}, {p0, 2, kForever}}, {{p2, 0, 0.5}, {p1, 1.5, kForever}}});
  ASSERT_FALSE(close.ok());
  EXPECT_NE(close.error().message.find("hold point r0c1 at once"), std::string::npos) << close.error().message;
}

TEST_F(TimeWindowsTest, TheCheckerFindsOppositeDirectionsOnOneLane) {
  TimeWindowRules rules;
  rules.headway_s = 0.0;  // clear 0.5 s: the points alone would let them pass
  // A drives r0c1 -> r0c2 over [0, 1], B drives r0c2 -> r0c1 over [0.2, 1.2].
  const auto head_on = CheckTimeWindows(*map, rules, {{{p1, 0, 0}, {p2, 1, 1}, {p3, 2, kForever}},
                                                     {{p2, -1, 0.2}, {p1, 1.2, 1.2}, {p0, 2.2, kForever}}});
  ASSERT_FALSE(head_on.ok());
  EXPECT_NE(head_on.error().message.find("opposite directions"), std::string::npos) << head_on.error().message;
}

// BIT2024 step 7's "first conflict" in the windows: the earliest overlap, with each robot's
// window (so one can be kept and forbidden to the other).
TEST_F(TimeWindowsTest, EarliestConflictIsTheFirstOverlapInTime) {
  TimeWindowRules rules;
  rules.headway_s = 0.0;  // clear 0.5 s
  ReservationTable table(map, rules);
  ASSERT_TRUE(table.Reserve(1, {{p0, 0, 0}, {p1, 1, 1}, {p2, 2, 2}, {p3, 3, kForever}}).ok());
  EXPECT_FALSE(EarliestConflict(table).has_value());
  // Robot 2 drives r0c2 -> r0c1 over [0.2, 1.2]: the lane r0c1-r0c2 both ways from 1.0, and
  // before that both at r0c1 from 1.0 as well; a later point conflict at r0c3 from 5.
  ASSERT_TRUE(table.Reserve(2, {{p2, -1, 0.2}, {p1, 1.2, 1.2}, {p0, 2.2, 4}, {p1, 5, 5}, {p2, 6, 6}, {p3, 7, kForever}}).ok());
  const auto c = EarliestConflict(table);
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->a.robot, 1);
  EXPECT_EQ(c->b.robot, 2);
  EXPECT_LT(c->at, 1.0 + 1e-9);
  EXPECT_GE(c->at, 0.2 - 1e-9);
  if (c->arc >= 0) {
    EXPECT_EQ(map->arc(c->arc).reverse_arc >= 0, true);
  } else {
    EXPECT_NE(c->point, kNoPoint);
  }
  ReservationTable apart(map, rules);
  ASSERT_TRUE(apart.Reserve(1, {{p0, 0, kForever}}).ok());
  ASSERT_TRUE(apart.Reserve(2, {{p3, 0, 0}, {p2, 1, kForever}}).ok());
  EXPECT_FALSE(EarliestConflict(apart).has_value());
  ASSERT_TRUE(apart.Reserve(3, {{p1, 10, 11}, {p0, 12, kForever}}).ok());  // r0c0 held for ever by 1
  const auto late = EarliestConflict(apart);
  ASSERT_TRUE(late.has_value());
  EXPECT_EQ(late->point, p0);
  EXPECT_DOUBLE_EQ(late->at, 12.0);
}

TEST_F(TimeWindowsTest, TheCheckerFindsALaneOverItsCapacity) {
  TimeWindowRules rules;
  rules.headway_s = 0.0;
  rules.body_length = 0.8;  // clear 0.8 s; a 1 m lane holds one robot (eq. (10))
  // One follows the other 0.8 s behind: the points are clear in time, the lane is not.
  const auto full = CheckTimeWindows(*map, rules, {{{p0, 0, 0}, {p1, 1, 1}, {p2, 2, 2}, {p3, 3, kForever}},
                                                  {{p0, 0.8, 0.8}, {p1, 1.8, 1.8}, {p2, 2.8, kForever}}});
  ASSERT_FALSE(full.ok());
  EXPECT_NE(full.error().message.find("more than 1 robots on the lane"), std::string::npos) << full.error().message;
}

TEST_F(TimeWindowsTest, TurningTakesItsTimePerRightAngle) {
  const auto l = GridMap({"..", "@."});
  TimeWindowRules rules;
  rules.turn_s_per_90 = 2.0;
  const ArcId east = *l->FindArc(At(*l, 0, 0), At(*l, 0, 1)), south = *l->FindArc(At(*l, 0, 1), At(*l, 1, 1));
  const ArcId west = *l->FindArc(At(*l, 0, 1), At(*l, 0, 0));
  EXPECT_DOUBLE_EQ(TurnTime(*l, rules, east, south), 2.0);
  EXPECT_DOUBLE_EQ(TurnTime(*l, rules, east, west), 4.0);  // a U-turn: 180 degrees
  EXPECT_DOUBLE_EQ(TurnTime(*l, rules, -1, south), 0.0);
  EXPECT_DOUBLE_EQ(DriveTime(*l, rules, east), 1.0);
  TimeWindowRules still;
  still.speed = 0.0;
  EXPECT_FALSE(still.Validate().ok());
}

}  // namespace
}  // namespace dispatch::engine
