// A robot's progress: arrivals, state reports, picks and drops that wait, drops of a team.
#include "engine/dispatch/robot_progress.h"

#include <gtest/gtest.h>

namespace dispatch::engine {
namespace {

Waypoint At(double x, WaypointAction action = WaypointAction::kMove) {
  Waypoint w;
  w.point = static_cast<PointId>(x);
  w.xy = Eigen::Vector2d(x, 0.0);
  w.action = action;
  return w;
}

// Anchor at x = 0, a move at 1, the pick at 3, a move at 4, the drop at 5 (sequences 0..4).
Assignment OneOrder() {
  Assignment a;
  a.robot_id = "R1";
  AppendOrder(a, "o1", {At(0), At(1), At(3, WaypointAction::kPick), At(4), At(5, WaypointAction::kDrop)}, 0.0,
              true, 0.0);
  return a;
}

TEST(RobotProgress, FreshArrivalsMoveTheRobotAndCountTheMetresOfTheirOrder) {
  const Assignment a = OneOrder();
  RobotProgress p;
  Arrival first = TakeArrival(p, a, 0, 4, Eigen::Vector2d(0.1, 0.0), 1.0);
  ASSERT_TRUE(first.verdict.taken);
  EXPECT_FALSE(first.fresh);  // sequence 0 is not above "nothing reached" (0)
  Arrival second = TakeArrival(p, a, 1, 4, std::nullopt, 1.0);
  ASSERT_TRUE(second.fresh);
  EXPECT_EQ(second.order, "o1");
  EXPECT_DOUBLE_EQ(second.driven, 0.0);  // no earlier arrival position
  ASSERT_TRUE(second.xy);
  EXPECT_DOUBLE_EQ(second.xy->x(), 1.0);  // no pose sent: the waypoint's
  Arrival third = TakeArrival(p, a, 2, 4, Eigen::Vector2d(3.2, 0.0), 1.0);
  ASSERT_TRUE(third.fresh);
  EXPECT_DOUBLE_EQ(third.driven, 2.0);  // waypoint to waypoint
  EXPECT_DOUBLE_EQ(third.xy->x(), 3.2);  // the pose it sent
  Arrival repeat = TakeArrival(p, a, 1, 4, std::nullopt, 1.0);
  EXPECT_TRUE(repeat.verdict.taken);
  EXPECT_FALSE(repeat.fresh);
  EXPECT_FALSE(repeat.xy);
  EXPECT_EQ(p.last_reached, 2u);
  // Not released, or far from its waypoint: nothing changes.
  EXPECT_FALSE(TakeArrival(p, a, 4, 3, std::nullopt, 1.0).verdict.taken);
  EXPECT_FALSE(TakeArrival(p, a, 3, 4, Eigen::Vector2d(9.0, 0.0), 1.0).verdict.taken);
  EXPECT_EQ(p.last_reached, 2u);
}

TEST(RobotProgress, AReportBeforeTheStopWaitsAndIsRetriedOnProgress) {
  const Assignment a = OneOrder();
  RobotProgress p;
  // A drop repeated after a restart: the robot stands at the drop but has not reported yet.
  TaskVerdict early = TakeTaskReport(p, a, {"o1", true}, Eigen::Vector2d(5.0, 0.0), 1.0);
  EXPECT_EQ(early.decision, TaskDecision::kWaiting);
  TakeTaskReport(p, a, {"o1", true}, Eigen::Vector2d(5.0, 0.0), 1.0);  // once per order and kind
  ASSERT_EQ(p.waiting.size(), 1u);
  std::uint64_t passed = 0;
  // A claim beyond anything numbered is not progress.
  EXPECT_TRUE(TakeStateProgress(p, a, 99, &passed).empty());
  EXPECT_EQ(passed, 0u);
  const std::vector<TaskReport> retry = TakeStateProgress(p, a, 4, &passed);
  EXPECT_EQ(passed, 4u);
  ASSERT_EQ(retry.size(), 1u);
  EXPECT_TRUE(p.waiting.empty());
  TaskVerdict now = TakeTaskReport(p, a, retry[0], Eigen::Vector2d(5.0, 0.0), 1.0);
  EXPECT_EQ(now.decision, TaskDecision::kTaken);
  EXPECT_EQ(now.index, 4u);
  // Far from the stop, or of an order it does not serve: rejected.
  EXPECT_EQ(TakeTaskReport(p, a, {"o1", true}, Eigen::Vector2d(0.0, 0.0), 1.0).decision, TaskDecision::kRejected);
  EXPECT_EQ(TakeTaskReport(p, a, {"o9", false}, Eigen::Vector2d(5.0, 0.0), 1.0).decision, TaskDecision::kRejected);
}

TEST(RobotProgress, WaitingReportsAreBounded) {
  Assignment a;
  a.robot_id = "R1";
  for (int k = 0; k < 10; ++k) {
    std::vector<Waypoint> seg = {At(1), At(2, WaypointAction::kDrop)};
    if (k == 0) seg.insert(seg.begin(), At(0));
    AppendOrder(a, "o" + std::to_string(k), seg, 0.0, false, 0.0);
  }
  RobotProgress p;
  bool overflowed = false;
  for (int k = 0; k < 10; ++k) {
    overflowed = TakeTaskReport(p, a, {"o" + std::to_string(k), true}, Eigen::Vector2d(2, 0), 1.0).overflowed || overflowed;
  }
  EXPECT_TRUE(overflowed);
  EXPECT_EQ(p.waiting.size(), kMaxWaitingReports);
  EXPECT_EQ(p.waiting.front().order_id, "o2");
}

TEST(RobotProgress, AFormationOrderCompletesWithItsLastMembersDrop) {
  const Assignment a = OneOrder();
  const std::vector<std::string> team = {"R1", "R2", "R3"};
  DropOutcome first = PlanDrop(a, "o1", "R1", team, {});
  EXPECT_TRUE(first.trimmed);
  EXPECT_TRUE(first.plan.order_ids.empty());
  EXPECT_FALSE(first.complete);
  DropOutcome last = PlanDrop(a, "o1", "R3", team, {"R1", "R2"});
  EXPECT_TRUE(last.complete);
  EXPECT_EQ(last.dropped_by.size(), 3u);
  EXPECT_FALSE(PlanDrop(a, "o2", "R1", {"R1"}, {}).trimmed);  // not its first order
}

}  // namespace
}  // namespace dispatch::engine
