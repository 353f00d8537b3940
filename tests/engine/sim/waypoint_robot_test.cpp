// WaypointRobot: the simulator's motion model following the core's messages.
#include "engine/sim/waypoint_robot.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

namespace dispatch::engine {
namespace {

// An assignment of move waypoints at (x, y) with their ETAs, all released.
RobotMessage Assignment(const std::vector<std::array<double, 3>>& points) {
  RobotMessage m;
  m.kind = RobotMessage::Kind::kAssignment;
  int seq = 1;
  for (const auto& [x, y, eta] : points) {
    MessageWaypoint w;
    w.waypoint.seq = seq++;
    w.waypoint.xy = {x, y};
    w.waypoint.eta = eta;
    m.waypoints.push_back(w);
  }
  m.released_up_to = static_cast<std::uint64_t>(seq - 1);
  return m;
}

// The time the robot reaches waypoint `seq`, stepping by dt.
double ReachTime(WaypointRobot& robot, std::uint64_t seq, double dt = 0.01) {
  std::vector<RobotEvent> events;
  for (double t = 0.0; t < 100.0; t += dt) {
    events.clear();
    robot.Step(t, events);
    if (robot.last_reached() >= seq) return t;
  }
  return -1.0;
}

TEST(WaypointRobotTest, DrivesItsPlanAtItsSpeed) {
  WaypointRobot robot("R1", {0.0, 0.0}, 1.0);
  robot.Apply(Assignment({{0, 0, 0}, {2, 0, 2}, {2, 2, 4}}));
  EXPECT_NEAR(ReachTime(robot, 3), 4.0, 0.011);
  EXPECT_TRUE(robot.idle());
  EXPECT_NEAR(robot.driven(), 4.0, 1e-9);
}

// Wang2019's turning time: a right angle costs turn_time standing, as BuildPlan times it;
// the first leg (from standing, heading unknown) turns nothing.
TEST(WaypointRobotTest, TurnsInPlaceWhereItsHeadingChanges) {
  WaypointRobot robot("R1", {0.0, 0.0}, 1.0, 1.5);
  robot.Apply(Assignment({{0, 0, 0}, {0, 2, 2}, {2, 2, 5.5}, {0, 2, 10.5}}));
  EXPECT_NEAR(ReachTime(robot, 2), 2.0, 0.011);  // north first: no turn
  WaypointRobot again("R2", {0.0, 0.0}, 1.0, 1.5);
  again.Apply(Assignment({{0, 0, 0}, {0, 2, 2}, {2, 2, 5.5}, {0, 2, 10.5}}));
  EXPECT_NEAR(ReachTime(again, 3), 5.5, 0.011);  // 90 degrees east: 1.5 s
  EXPECT_NEAR(ReachTime(again, 4), 10.5, 0.011);  // a U-turn: 3 s
  WaypointRobot plain("R3", {0.0, 0.0}, 1.0);
  plain.Apply(Assignment({{0, 0, 0}, {0, 2, 0}, {2, 2, 0}}));
  EXPECT_NEAR(ReachTime(plain, 3), 4.0, 0.011);  // no turning time: straight on
}

}  // namespace
}  // namespace dispatch::engine
