// The rules of a robot's stream the dispatcher applies itself (server/robot_protocol.h): Hello
// first and once, a live stream is not taken over, acks only of what was sent, the heartbeat
// timeout and the offline grace; and what a waypoint says on the wire.
#include "server/robot_protocol.h"

#include <gtest/gtest.h>

#include <cctype>
#include <chrono>
#include <numbers>
#include <string>

#include "server/proto_convert.h"

namespace dispatch::server {
namespace {

using Clock = RobotSession::Clock;
using Kind = RobotInbound::Kind;
using std::chrono::milliseconds;
using std::chrono::seconds;

TEST(RobotProtocolTest, AStreamStartsWithOneHello) {
  EXPECT_FALSE(OutOfTurn(Kind::kHello, false).has_value());
  EXPECT_EQ(OutOfTurn(Kind::kHello, true).value_or(""), "Hello sent twice on one stream");
  for (Kind kind : {Kind::kState, Kind::kWaypointReached, Kind::kTaskEvent, Kind::kHeartbeat, Kind::kAck}) {
    EXPECT_EQ(OutOfTurn(kind, false).value_or(""), "the first message of a stream must be Hello");
    EXPECT_FALSE(OutOfTurn(kind, true).has_value());
  }
}

TEST(RobotProtocolTest, ALiveStreamIsKeptUntilItsHeartbeatTimesOut) {
  const Clock::time_point t0{};
  RobotSession s;
  s.last_heard = t0;
  const auto live = LiveStream("R1", s, t0 + seconds(2), 5.0);
  ASSERT_TRUE(live.has_value());
  EXPECT_EQ(*live, "robot R1 already has a live stream (heard 2.00 s ago); retry after its heartbeat times out");
  EXPECT_TRUE(LiveStream("R1", s, t0 + seconds(5), 5.0).has_value());  // exactly at the timeout: still live
  EXPECT_FALSE(LiveStream("R1", s, t0 + milliseconds(5001), 5.0).has_value());
}

TEST(RobotProtocolTest, OnlyAnAckOfASequenceSentCounts) {
  RobotSession s;
  s.next_sequence = 8;
  s.last_acked_sequence = 3;
  TakeAck(s, 5);
  EXPECT_EQ(s.last_acked_sequence, 5u);
  TakeAck(s, 4);  // late: never goes back
  EXPECT_EQ(s.last_acked_sequence, 5u);
  TakeAck(s, 8);  // not sent yet
  TakeAck(s, ~0ull);
  EXPECT_EQ(s.last_acked_sequence, 5u);
  TakeAck(s, 7);
  EXPECT_EQ(s.last_acked_sequence, 7u);
}

TEST(RobotProtocolTest, ASilentRobotGoesOfflineAfterTheHeartbeatTimeout) {
  const Clock::time_point t0{};
  RobotSession s;
  s.last_heard = t0;
  EXPECT_FALSE(SilenceTimeout(s, t0 + seconds(5), 5.0).has_value());
  EXPECT_EQ(SilenceTimeout(s, t0 + seconds(6), 5.0).value_or(""), "no message for 6.00 s (heartbeat timeout 5.00 s)");
}

TEST(RobotProtocolTest, ARobotOfflineWithOrdersLosesThemAfterTheGrace) {
  const Clock::time_point t0{};
  engine::BookRobot robot;
  robot.robot.id = "R1";
  RobotSession s;
  s.offline_since = t0;
  EXPECT_FALSE(HasOrders(nullptr));
  EXPECT_FALSE(HasOrders(&robot));
  EXPECT_FALSE(GraceOver("R1", s, &robot, t0 + seconds(60), 10.0).has_value());  // no orders
  robot.has_assignment = true;
  EXPECT_FALSE(HasOrders(&robot));  // a plan with no orders
  robot.assignment.order_ids = {"ord-000001"};
  ASSERT_TRUE(HasOrders(&robot));
  EXPECT_FALSE(GraceOver("R1", s, &robot, t0 + seconds(9), 10.0).has_value());
  EXPECT_EQ(GraceOver("R1", s, &robot, t0 + seconds(10), 10.0).value_or(""), "robot R1 offline for more than 10.00 s");
  EXPECT_FALSE(GraceOver("R1", s, nullptr, t0 + seconds(60), 10.0).has_value());  // unknown to the core
  s.offline_since.reset();  // its orders went back already
  EXPECT_FALSE(GraceOver("R1", s, &robot, t0 + seconds(60), 10.0).has_value());
}

// A four-wheel-steer robot's waypoint in a free-space region carries its heading and motion
// mode; a waypoint on the road graph has neither (so older robots see nothing new).
TEST(RobotProtocolTest, AWaypointCarriesHeadingAndModeOnlyInAFreeSpace) {
  OutboundWaypoint w;
  w.waypoint.seq = 7;
  w.waypoint.point = 3;
  w.waypoint.xy = {4.5, 1.825};
  w.waypoint.action = engine::WaypointAction::kPick;
  RobotOutbound m;
  m.kind = RobotOutbound::Kind::kAssignment;
  m.waypoints = {w};
  w.waypoint.heading = std::numbers::pi / 2;
  w.waypoint.mode = engine::MotionMode::kCrabLeft;
  m.waypoints.push_back(w);
  pb::ServerMessage out;
  OutboundToProto(m, &out);
  ASSERT_EQ(out.assignment().waypoints_size(), 2);
  const pb::TimedWaypoint& lane = out.assignment().waypoints(0);
  EXPECT_FALSE(lane.has_heading());
  EXPECT_EQ(lane.motion_mode(), pb::MOTION_MODE_UNSPECIFIED);
  const pb::TimedWaypoint& slot = out.assignment().waypoints(1);
  ASSERT_TRUE(slot.has_heading());
  EXPECT_DOUBLE_EQ(slot.heading(), std::numbers::pi / 2);
  EXPECT_EQ(slot.motion_mode(), pb::MOTION_MODE_CRAB_LEFT);
  EXPECT_EQ(slot.action(), pb::WAYPOINT_ACTION_PICK);
  for (int m = 0; m <= static_cast<int>(engine::MotionMode::kArcReverseRight); ++m) {
    const auto mode = static_cast<engine::MotionMode>(m);
    EXPECT_EQ(pb::MotionMode_Name(MotionModeToProto(mode)), "MOTION_MODE_" + [&] {
      std::string name = engine::MotionModeName(mode);
      for (char& c : name) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
      return name;
    }()) << engine::MotionModeName(mode);
  }
}

}  // namespace
}  // namespace dispatch::server
