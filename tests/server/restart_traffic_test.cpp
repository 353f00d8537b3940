// Traffic control across a restart (Dispatcher, "Restart"): robots that were on line when the
// old process stopped may have driven on since their stored record, so the gate releases
// nothing (no Grant, nothing released in the resent plan beyond the robot's point) until
// every one of them has reconnected and reported, or heartbeat_timeout has passed.
#include <gtest/gtest.h>

#include <chrono>
#include <set>
#include <thread>

#include "server/dispatcher.h"
#include "tests/server/test_support.h"

namespace dispatch::server::testing {
namespace {

// park-P1 and park-P2 of the Chu2024 floor.
constexpr double kP1x = 3.875, kP1y = -1.25;
constexpr double kP2x = 9.75, kP2y = -1.25;

struct Start {
  const char* id;
  double x, y;
};
constexpr Start kRobots[] = {{"R1", kP1x, kP1y}, {"R2", kP2x, kP2y}};

class RestartTrafficTest : public ::testing::Test {
 protected:
  void StartServer() {
    auto started = DispatchServer::Start(config_);
    ASSERT_TRUE(started.ok()) << started.error().message;
    server_ = std::move(started).value();
    channel_ = ChannelTo(*server_);
  }
  void StopServer() {
    channel_.reset();
    server_.reset();
  }
  // Both robots on line, an order on one of them, and the server stops while both are still
  // connected (their records say they were on line). Returns the robot with the order.
  std::string AssignAndStopWithTheFleetOnLine() {
    StartServer();
    OrderWatcher watcher(channel_);
    FakeRobot r1(channel_, kRobots[0].id), r2(channel_, kRobots[1].id);
    r1.Connect(kRobots[0].x, kRobots[0].y);
    r2.Connect(kRobots[1].x, kRobots[1].y);
    EXPECT_TRUE(r1.WaitFor(pb::ServerMessage::kWelcome));
    EXPECT_TRUE(r2.WaitFor(pb::ServerMessage::kWelcome));
    auto orders = pb::OrderService::NewStub(channel_);
    grpc::ClientContext ctx;
    pb::SubmitOrderResponse submitted;
    EXPECT_TRUE(orders->SubmitOrder(WithDeadline(ctx), OrderRequest("wms-1", {"K3-2-3N"}, "D-B2"), &submitted).ok());
    auto assigned = watcher.WaitForState(submitted.order().id(), pb::ORDER_STATE_ASSIGNED);
    EXPECT_TRUE(assigned && assigned->robot_ids_size() == 1);
    StopServer();  // the robots' streams end with the server, not before it
    return assigned && assigned->robot_ids_size() == 1 ? assigned->robot_ids(0) : std::string();
  }
  static const Start& StartOf(const std::string& id) { return id == kRobots[0].id ? kRobots[0] : kRobots[1]; }
  static void Report(FakeRobot& robot, const Start& at) {
    pb::RobotMessage m;
    m.mutable_state_report()->mutable_pose()->set_x(at.x);
    m.mutable_state_report()->mutable_pose()->set_y(at.y);
    m.mutable_state_report()->set_state(pb::ROBOT_STATE_IDLE);
    ASSERT_TRUE(robot.Write(m));
  }
  // Waits (up to the tests' timeout) until the published snapshot satisfies `done`.
  bool WaitForSnapshot(const std::function<bool(const Snapshot&)>& done) {
    const auto deadline = std::chrono::steady_clock::now() + kTimeout;
    while (std::chrono::steady_clock::now() < deadline) {
      if (done(*server_->dispatcher().snapshot())) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));  // polling a condition
    }
    return false;
  }

  TempDir dir_;
  ServerConfig config_ = [this] {
    ServerConfig c = TestConfig(dir_.File("dispatch.db"));
    c.time_scale = 50.0;
    return c;
  }();
  std::unique_ptr<DispatchServer> server_;
  std::shared_ptr<grpc::Channel> channel_;
};

TEST_F(RestartTrafficTest, NothingIsReleasedUntilEveryRobotThatWasOnLineHasReported) {
  const std::string busy = AssignAndStopWithTheFleetOnLine();
  ASSERT_FALSE(busy.empty());
  const std::string other = busy == kRobots[0].id ? kRobots[1].id : kRobots[0].id;
  StartServer();
  EXPECT_EQ(server_->dispatcher().snapshot()->traffic.awaiting_reconnect,
            (std::vector<std::string>{kRobots[0].id, kRobots[1].id}));

  // The robot with work is back and reports; its plan comes, but no release beyond its point.
  FakeRobot first(channel_, busy);
  first.Connect(StartOf(busy).x, StartOf(busy).y);
  auto plan = first.WaitFor(pb::ServerMessage::kAssignment);
  ASSERT_TRUE(plan);
  const auto& waypoints = plan->assignment().waypoints();
  ASSERT_GT(waypoints.size(), 1);
  EXPECT_LT(plan->assignment().released_up_to_sequence(), waypoints[waypoints.size() - 1].sequence());
  Report(first, StartOf(busy));
  ASSERT_TRUE(WaitForSnapshot([&](const Snapshot& s) {
    return s.traffic.awaiting_reconnect == std::vector<std::string>{other};
  })) << "the first robot's report did not count";

  // The other robot comes back: from its report on, traffic control runs again.
  FakeRobot second(channel_, other);
  second.Connect(StartOf(other).x, StartOf(other).y);
  auto welcome = second.WaitFor(pb::ServerMessage::kWelcome);
  ASSERT_TRUE(welcome);
  // Connected is not enough: where it is counts, so the wait ends with its report.
  ASSERT_TRUE(WaitForSnapshot([&](const Snapshot& s) {
    auto r = s.robots.find(other);
    return r != s.robots.end() && r->second.connected;
  }));
  EXPECT_EQ(server_->dispatcher().snapshot()->traffic.awaiting_reconnect, std::vector<std::string>{other});
  Report(second, StartOf(other));
  auto grant = first.WaitFor(pb::ServerMessage::kGrant);
  ASSERT_TRUE(grant) << "no release after every robot had reported";
  EXPECT_GE(grant->server_time(), welcome->server_time())
      << "a release went out while " << other << " had not reconnected";
  // (Grants go out before the next snapshot is published.)
  EXPECT_TRUE(WaitForSnapshot([](const Snapshot& s) { return s.traffic.awaiting_reconnect.empty(); }));
}

TEST_F(RestartTrafficTest, ARobotThatDoesNotComeBackIsWaitedForOneHeartbeatTimeout) {
  const std::string busy = AssignAndStopWithTheFleetOnLine();
  ASSERT_FALSE(busy.empty());
  config_.heartbeat_timeout = 1.0;  // wall seconds, from the restart on
  StartServer();
  const double restarted = server_->dispatcher().snapshot()->time;
  FakeRobot first(channel_, busy);
  first.Connect(StartOf(busy).x, StartOf(busy).y);
  ASSERT_TRUE(first.WaitFor(pb::ServerMessage::kAssignment));
  Report(first, StartOf(busy));
  // (Heartbeats keep its own stream alive through the wait.)
  std::optional<pb::ServerMessage> grant;
  const auto deadline = std::chrono::steady_clock::now() + kTimeout;
  while (!grant && std::chrono::steady_clock::now() < deadline) {
    first.Heartbeat();
    grant = first.WaitFor(pb::ServerMessage::kGrant, std::chrono::milliseconds(200));
  }
  ASSERT_TRUE(grant) << "traffic control never resumed without the other robot";
  // Dispatcher seconds run time_scale times faster than wall seconds.
  EXPECT_GE(grant->server_time() - restarted, 0.9 * config_.heartbeat_timeout * config_.time_scale);
  EXPECT_TRUE(WaitForSnapshot([](const Snapshot& s) { return s.traffic.awaiting_reconnect.empty(); }));
}

}  // namespace
}  // namespace dispatch::server::testing
