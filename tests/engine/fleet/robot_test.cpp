#include "engine/fleet/robot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

namespace dispatch::engine {
namespace {

TEST(RobotTest, StateNamesRoundTrip) {
  const std::vector<RobotState> all = {RobotState::kIdle,    RobotState::kMoving,
                                       RobotState::kWorking, RobotState::kWaiting,
                                       RobotState::kParked,  RobotState::kCharging,
                                       RobotState::kFault,   RobotState::kOffline};
  std::set<std::string> names;
  for (RobotState s : all) {
    EXPECT_EQ(ParseRobotState(RobotStateName(s)), s);
    names.insert(RobotStateName(s));
  }
  EXPECT_EQ(names.size(), all.size());
  EXPECT_FALSE(ParseRobotState("sleeping").has_value());
}

TEST(RobotTest, DefaultsAndValidation) {
  Robot r;
  r.id = "R1";
  EXPECT_EQ(r.diameter, 0.4);
  EXPECT_EQ(r.state, RobotState::kIdle);
  EXPECT_EQ(r.current_point, kNoPoint);
  EXPECT_FALSE(r.battery.has_value());
  EXPECT_TRUE(ValidateRobot(r).ok());

  Robot no_id = r;
  no_id.id.clear();
  EXPECT_FALSE(ValidateRobot(no_id).ok());

  Robot slow = r;
  slow.max_speed = 0.0;
  ASSERT_FALSE(ValidateRobot(slow).ok());
  EXPECT_NE(ValidateRobot(slow).error().message.find("'R1'"), std::string::npos);
  EXPECT_NE(ValidateRobot(slow).error().message.find("speed"), std::string::npos);

  Robot drained = r;
  drained.battery = 1.5;
  ASSERT_FALSE(ValidateRobot(drained).ok());
  EXPECT_NE(ValidateRobot(drained).error().message.find("battery"), std::string::npos);

  Robot lost = r;
  lost.pose.heading = std::nan("");
  EXPECT_FALSE(ValidateRobot(lost).ok());
}

}  // namespace
}  // namespace dispatch::engine
