// Robot intake: ids, poses on and off the map, and the messages that say why.
#include "engine/dispatch/robot_intake.h"

#include <gtest/gtest.h>

#include <limits>

#include "tests/engine/dispatch/dispatch_test_support.h"

namespace dispatch::engine {
namespace {

using testing_util::Chu2024;

Pose At(double x, double y, double heading = 0.0) {
  Pose p;
  p.position = Eigen::Vector2d(x, y);
  p.heading = heading;
  return p;
}

TEST(RobotIntake, IdsAreShortPlainNames) {
  EXPECT_TRUE(ValidRobotId("R1"));
  EXPECT_TRUE(ValidRobotId("amr_07.left-B"));
  EXPECT_FALSE(ValidRobotId(""));
  EXPECT_FALSE(ValidRobotId(std::string(65, 'a')));
  EXPECT_FALSE(ValidRobotId("R 1"));
  EXPECT_FALSE(ValidRobotId("R/1"));
}

TEST(RobotIntake, APoseNearAPointOrALaneLocatesTheRobot) {
  const auto& map = *Chu2024();
  const PointId p1 = *map.FindPoint("park-P1");
  const Eigen::Vector2d at = map.point(p1).position;
  auto exact = LocateRobot(map, "R1", At(at.x(), at.y()), 1.0);
  ASSERT_TRUE(exact.ok()) << exact.error().message;
  EXPECT_EQ(*exact, p1);
  auto near = LocateRobot(map, "R1", At(at.x() + 0.3, at.y()), 1.0);
  ASSERT_TRUE(near.ok());
  EXPECT_EQ(*near, map.NearestPoint(Eigen::Vector2d(at.x() + 0.3, at.y())));
  // Half-way along a lane, farther than the tolerance from every point: the point it drives to.
  const Arc& arc = map.arcs().front();
  const Eigen::Vector2d mid = 0.5 * (map.point(arc.from).position + map.point(arc.to).position);
  const double off = (map.point(map.NearestPoint(mid)).position - mid).norm();
  ASSERT_GT(off, 0.0);
  auto on_lane = LocateRobot(map, "R1", At(mid.x(), mid.y()), 0.5 * off);
  ASSERT_TRUE(on_lane.ok()) << on_lane.error().message;
  EXPECT_TRUE(*on_lane == arc.to || *on_lane == arc.from) << map.point(*on_lane).name;  // either direction
  EXPECT_FALSE(LocateRobot(map, "R1", At(mid.x() + 50.0, mid.y() + 50.0), 0.5 * off).ok());
}

TEST(RobotIntake, BadIdsAndPosesAreRefusedWithTheReason) {
  const auto& map = *Chu2024();
  auto bad_id = LocateRobot(map, "R 1", At(0, 0), 1.0);
  ASSERT_FALSE(bad_id.ok());
  EXPECT_EQ(bad_id.error().message, "robot id 'R 1' is invalid: use 1-64 letters, digits, '_', '-' or '.'");
  auto nan = LocateRobot(map, "R1", At(std::numeric_limits<double>::quiet_NaN(), 0), 1.0);
  ASSERT_FALSE(nan.ok());
  EXPECT_EQ(nan.error().message, "robot R1: pose is not finite");
  auto far = LocateRobot(map, "R1", At(1e300, 0), 1.0);
  ASSERT_FALSE(far.ok());
  EXPECT_NE(far.error().message.find("pose (1e+300, 0.00) is not on the map"), std::string::npos)
      << far.error().message;
  EXPECT_NE(far.error().message.find("tolerance 1.00 m"), std::string::npos);
  EXPECT_FALSE(OnFloor(map, Eigen::Vector2d(1e300, 0), 1.0));
  EXPECT_TRUE(OnFloor(map, map.point(0).position, 0.0));
  EXPECT_EQ(FormatFixed(2.345), "2.35");
  EXPECT_EQ(FormatFixed(1e300), "1e+300");
}

}  // namespace
}  // namespace dispatch::engine
