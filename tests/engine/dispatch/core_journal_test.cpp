// The journal's output lines (core_journal.h): a plan is named by a digest of its waypoints,
// so a replay that plans differently shows it.
#include "engine/dispatch/core_journal.h"

#include <gtest/gtest.h>

#include <string>

namespace dispatch::engine {
namespace {

Change PlanOf(std::vector<Waypoint> waypoints) {
  Change c;
  Assignment a;
  a.robot_id = "R1";
  a.plan_id = 1;
  a.order_ids = {"o1"};
  a.plan.robot_id = "R1";
  a.plan.waypoints = std::move(waypoints);
  c.plans["R1"] = a;
  return c;
}

// A four-wheel-steer plan's poses (issue 17 §3): two plans through the same points at the same
// times that differ only in a heading or a motion mode are two plans in the journal; a plan
// without poses keeps the line it always had.
TEST(CoreJournalTest, APlansDigestCountsItsPoses) {
  Waypoint a{0, 3, {1.0, 2.0}, 0.0, WaypointAction::kMove, 0.0, {}, {}};
  Waypoint b{1, 4, {2.0, 2.0}, 1.0, WaypointAction::kPick, 5.0, {}, {}};
  const std::string lanes = DescribeChange(PlanOf({a, b}));
  EXPECT_EQ(lanes, DescribeChange(PlanOf({a, b})));
  EXPECT_NE(lanes.find("R1 plan p1 2 wp #"), std::string::npos) << lanes;

  Waypoint posed = b;
  posed.heading = 3.14159;
  posed.mode = MotionMode::kSpinLeft;
  const std::string spun = DescribeChange(PlanOf({a, posed}));
  EXPECT_NE(spun, lanes);
  Waypoint other_heading = posed;
  other_heading.heading = 0.0;
  EXPECT_NE(DescribeChange(PlanOf({a, other_heading})), spun);
  Waypoint other_mode = posed;
  other_mode.mode = MotionMode::kSpinRight;
  EXPECT_NE(DescribeChange(PlanOf({a, other_mode})), spun);
}

}  // namespace
}  // namespace dispatch::engine
