// The plan book's rules: segments per order, life-long waypoint numbering, cuts and trims.
#include "engine/dispatch/assignment.h"

#include <gtest/gtest.h>

namespace dispatch::engine {
namespace {

Waypoint At(PointId p, double eta, WaypointAction action = WaypointAction::kMove, double dwell = 0.0) {
  Waypoint w;
  w.point = p;
  w.xy = Eigen::Vector2d(static_cast<double>(p), 0.0);
  w.eta = eta;
  w.action = action;
  w.dwell = dwell;
  return w;
}

// From point `from`: a move, a pick, a drop (4 waypoints, the first the segment's start).
std::vector<Waypoint> Leg(PointId from, double t0) {
  return {At(from, t0), At(from + 1, t0 + 1), At(from + 2, t0 + 2, WaypointAction::kPick, 5),
          At(from + 3, t0 + 8, WaypointAction::kDrop, 5)};
}

Assignment TwoOrders() {
  Assignment a;
  a.robot_id = "R1";
  AppendOrder(a, "o1", Leg(10, 0), 0.0, true, 1.0);
  std::vector<Waypoint> second = Leg(13, 13);
  second.erase(second.begin());  // a queued order's segment starts after the queue's end point
  AppendOrder(a, "o2", second, 13.0, false, 2.0);
  return a;
}

TEST(Assignment, AppendNumbersWaypointsLifeLongAndSegmentsFollowTheDrops) {
  Assignment a = TwoOrders();
  ASSERT_EQ(a.plan.waypoints.size(), 7u);
  for (std::size_t i = 0; i < a.plan.waypoints.size(); ++i) EXPECT_EQ(a.plan.waypoints[i].seq, static_cast<int>(i));
  EXPECT_EQ(a.plan_id, 1u);
  EXPECT_EQ(a.released_up_to, 6);
  EXPECT_EQ(a.plan.robot_id, "R1");
  EXPECT_EQ(a.updated_time, 2.0);
  EXPECT_EQ(SegmentStart(a, 0), 1u);
  EXPECT_EQ(SegmentStart(a, 1), 4u);
  EXPECT_EQ(SegmentStart(a, 2), 7u);
  EXPECT_EQ(SegmentStarts(a), (std::vector<std::size_t>{1, 4, 7}));
  const std::vector<std::string> of = OrdersOfWaypoints(a);
  EXPECT_EQ(of, (std::vector<std::string>{"", "o1", "o1", "o1", "o2", "o2", "o2"}));
  for (std::size_t i = 0; i < of.size(); ++i) EXPECT_EQ(OrderOfWaypoint(a, i), of[i]) << i;
  EXPECT_EQ(NextSequence(a), 7u);
  EXPECT_EQ(FindWaypoint(a, 5), 5u);
  EXPECT_EQ(FindWaypoint(a, 99), static_cast<std::size_t>(-1));
}

TEST(Assignment, QueuedSegmentNeverStartsBeforeTheStoredPlanEnds) {
  Assignment a;
  a.robot_id = "R1";
  AppendOrder(a, "o1", Leg(10, 0), 0.0, true, 0.0);  // ends at 8 + 5 = 13
  // Planned on a re-timed queue whose end departure was 10: shifted by 3 s.
  std::vector<Waypoint> second = {At(20, 11), At(21, 12, WaypointAction::kDrop, 5)};
  AppendOrder(a, "o2", second, 10.0, false, 0.0);
  EXPECT_DOUBLE_EQ(a.plan.waypoints[4].eta, 14.0);
  EXPECT_DOUBLE_EQ(a.plan.waypoints[5].eta, 15.0);
  // Planned after the real end: not moved earlier.
  AppendOrder(a, "o3", {At(30, 40), At(31, 41, WaypointAction::kDrop)}, 30.0, false, 0.0);
  EXPECT_DOUBLE_EQ(a.plan.waypoints[6].eta, 40.0);
}

TEST(Assignment, CutRemovesTheOrderAndLaterOnesButNeverReusesSequences) {
  Assignment a = TwoOrders();
  EXPECT_TRUE(CutPlan(a, "nope").empty());
  EXPECT_EQ(a.order_ids.size(), 2u);
  const std::vector<std::string> later = CutPlan(a, "o1");
  EXPECT_EQ(later, std::vector<std::string>{"o2"});
  EXPECT_TRUE(a.order_ids.empty());
  ASSERT_EQ(a.plan.waypoints.size(), 1u);  // the anchor
  EXPECT_EQ(a.released_up_to, 6);
  EXPECT_EQ(NextSequence(a), 7u);
  // The next award starts a new plan, numbered above everything issued before.
  const std::uint64_t first = AppendOrder(a, "o3", Leg(40, 50), 0.0, false, 3.0);
  EXPECT_EQ(first, 7u);
  EXPECT_EQ(a.plan_id, 2u);
  EXPECT_EQ(a.plan.waypoints.front().seq, 7);
}

TEST(Assignment, TrimDoneMakesTheDropTheNewAnchor) {
  Assignment a = TwoOrders();
  EXPECT_FALSE(TrimDone(a, "o2"));  // not the first order
  ASSERT_TRUE(TrimDone(a, "o1"));
  EXPECT_EQ(a.order_ids, std::vector<std::string>{"o2"});
  ASSERT_EQ(a.plan.waypoints.size(), 4u);
  EXPECT_EQ(a.plan.waypoints.front().seq, 3);  // o1's drop
  EXPECT_EQ(a.plan.waypoints.front().action, WaypointAction::kDrop);
  EXPECT_EQ(OrdersOfWaypoints(a), (std::vector<std::string>{"", "o2", "o2", "o2"}));
  ASSERT_TRUE(TrimDone(a, "o2"));
  EXPECT_TRUE(a.order_ids.empty());
  EXPECT_EQ(a.plan.waypoints.size(), 1u);
  // An empty plan trims and cuts without touching waypoints it does not have.
  Assignment empty;
  empty.order_ids = {"x"};
  EXPECT_TRUE(TrimDone(empty, "x"));
  empty.order_ids = {"y"};
  EXPECT_TRUE(CutPlan(empty, "y").empty());
  EXPECT_TRUE(empty.plan.waypoints.empty());
}

TEST(Assignment, GatePlanCarriesOrdersTeamsAndTheNextSequence) {
  Assignment a = TwoOrders();
  a.released_up_to = 9;  // issued once, then cut away
  const GatePlan g = ToGatePlan(a, {{"o2", {"R1", "R2", "R3"}}});
  EXPECT_EQ(g.waypoints.size(), 7u);
  EXPECT_EQ(g.order_of, OrdersOfWaypoints(a));
  EXPECT_EQ(g.next_sequence, 10u);
  EXPECT_EQ(g.teams.at("o2").size(), 3u);
  EXPECT_EQ(HighestNumbered(Assignment{}), -1);
}

// A robot's arrivals in plan order with the cursor, while its plan loses finished orders, is
// cut, grows and is rewritten behind it (a gate's detour: new sequences after the reached
// waypoint): the same order as the scan from the plan's start at every arrival.
TEST(Assignment, OrderCursorAgreesWithTheScanWhileThePlanChanges) {
  Assignment a = TwoOrders();
  AppendOrder(a, "o3", {At(17, 30), At(18, 31, WaypointAction::kPick, 2), At(19, 35, WaypointAction::kDrop, 2)},
              30.0, false, 3.0);
  OrderCursor cursor;
  int checked = 0;
  auto arrive = [&](std::size_t index) {
    ASSERT_LT(index, a.plan.waypoints.size());
    const std::string scan = OrderOfWaypoint(a, index);
    EXPECT_EQ(OrderOfWaypoint(a, index, cursor), scan) << "index " << index << " seq " << a.plan.waypoints[index].seq;
    ++checked;
  };
  for (std::size_t i = 1; i <= 3; ++i) arrive(i);  // o1 up to its drop
  ASSERT_TRUE(TrimDone(a, "o1"));                   // the drop is the new anchor
  arrive(0);
  arrive(1);
  arrive(2);
  // A detour after waypoint 2: the rest renumbered from the next sequence.
  std::vector<Waypoint> rest(a.plan.waypoints.begin() + 3, a.plan.waypoints.end());
  a.plan.waypoints.resize(3);
  std::uint64_t next = NextSequence(a);
  a.plan.waypoints.push_back(At(40, 20));
  for (Waypoint w : rest) {
    w.seq = static_cast<int>(next++);
    a.plan.waypoints.push_back(w);
  }
  a.released_up_to = a.plan.waypoints.back().seq;
  for (std::size_t i = 3; i < a.plan.waypoints.size(); ++i) arrive(i);
  // Cut after o2, then a new order: the cursor's waypoint (o3's drop) is gone.
  EXPECT_EQ(CutPlan(a, "o3"), std::vector<std::string>{});
  AppendOrder(a, "o4", {At(50, 40), At(51, 41, WaypointAction::kPick, 2), At(52, 45, WaypointAction::kDrop, 2)},
              40.0, false, 4.0);
  for (std::size_t i = 1; i < a.plan.waypoints.size(); ++i) arrive(i);
  // Arrivals out of order (a repeat before the cursor) and past the last drop.
  arrive(1);
  a.plan.waypoints.push_back(At(60, 60));
  a.plan.waypoints.back().seq = static_cast<int>(NextSequence(a));
  arrive(a.plan.waypoints.size() - 1);
  arrive(2);
  EXPECT_GE(checked, 20);
  EXPECT_EQ(OrderOfWaypoint(a, a.plan.waypoints.size() - 2, cursor), "o4");  // the drop
}

}  // namespace
}  // namespace dispatch::engine
