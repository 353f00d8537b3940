// Operators' commands on robots through the running service (issue 18 §4; OperatorService and
// REST POST /api/v1/robots/{id}/...): out of service gives the robot's order to another robot
// (the event names why) and is kept across a restart until the robot is returned; an offline
// robot is cleared off the floor, a connected one is not; an idle robot is sent to a station
// (its plan ends at the station's park point) and an unknown station is NOT_FOUND.
#include "tests/server/test_support.h"
#include "warehouse/dispatch/v1/operator.grpc.pb.h"

#include <httplib.h>  // after every header that pulls in Eigen (STYLE.md)

#include <string>

namespace dispatch::server::testing {
namespace {

// park-P1 and park-P2 of the Chu2024 floor.
constexpr double kP1x = 3.875, kP1y = -1.25;
constexpr double kP2x = 9.75, kP2y = -1.25;

class RobotCommandsServiceTest : public ::testing::Test {
 protected:
  void StartServer() {
    auto started = DispatchServer::Start(config_);
    ASSERT_TRUE(started.ok()) << started.error().message;
    server_ = std::move(started).value();
    channel_ = ChannelTo(*server_);
    operators_ = pb::OperatorService::NewStub(channel_);
    orders_ = pb::OrderService::NewStub(channel_);
  }
  void StopServer() {
    operators_.reset();
    orders_.reset();
    channel_.reset();
    server_.reset();
  }
  grpc::Status Call(grpc::Status (pb::OperatorService::Stub::*rpc)(grpc::ClientContext*, const pb::RobotCommandRequest&,
                                                                     pb::RobotInfo*),
                    const std::string& robot, pb::RobotInfo* out) {
    grpc::ClientContext ctx;
    pb::RobotCommandRequest request;
    request.set_robot_id(robot);
    return (operators_.get()->*rpc)(WithDeadline(ctx), request, out);
  }
  grpc::Status Send(const std::string& robot, const std::string& station, pb::RobotInfo* out) {
    grpc::ClientContext ctx;
    pb::SendRobotRequest request;
    request.set_robot_id(robot);
    request.set_station(station);
    return operators_->SendRobot(WithDeadline(ctx), request, out);
  }
  std::string Submit(const std::string& client_id) {
    grpc::ClientContext ctx;
    pb::SubmitOrderResponse submitted;
    EXPECT_TRUE(orders_->SubmitOrder(WithDeadline(ctx), OrderRequest(client_id, {"K3-2-3N"}, "D-B2"), &submitted).ok());
    return submitted.order().id();
  }

  TempDir dir_;
  ServerConfig config_ = [this] {
    ServerConfig c = TestConfig(dir_.File("dispatch.db"));
    c.time_scale = 50.0;
    return c;
  }();
  std::unique_ptr<DispatchServer> server_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<pb::OperatorService::Stub> operators_;
  std::unique_ptr<pb::OrderService::Stub> orders_;
};

TEST_F(RobotCommandsServiceTest, OutOfServiceHandsTheOrderOnAndLastsAcrossARestartUntilReturned) {
  StartServer();
  {
    OrderWatcher watcher(channel_);
    FakeRobot r1(channel_, "R1"), r2(channel_, "R2");
    r1.Connect(kP1x, kP1y);
    ASSERT_TRUE(r1.WaitFor(pb::ServerMessage::kWelcome));
    const std::string order = Submit("wms-1");
    auto assigned = watcher.WaitForState(order, pb::ORDER_STATE_ASSIGNED);
    ASSERT_TRUE(assigned && assigned->robot_ids_size() == 1 && assigned->robot_ids(0) == "R1");
    ASSERT_TRUE(r1.WaitFor(pb::ServerMessage::kAssignment));

    pb::RobotInfo info;
    ASSERT_TRUE(Call(&pb::OperatorService::Stub::TakeOutOfService, "R1", &info).ok());
    EXPECT_EQ(info.out_of_service_by(), "an operator");
    EXPECT_EQ(info.order_ids_size(), 0);
    auto cancel = r1.WaitFor(pb::ServerMessage::kCancel);
    ASSERT_TRUE(cancel) << "R1 was not told to drop its order";
    auto back = watcher.WaitForState(order, pb::ORDER_STATE_ACCEPTED);
    ASSERT_TRUE(back);
    EXPECT_NE(back->detail().find("taken out of service by an operator"), std::string::npos) << back->detail();
    r2.Connect(kP2x, kP2y);
    auto again = watcher.WaitForState(order, pb::ORDER_STATE_ASSIGNED);
    ASSERT_TRUE(again && again->robot_ids_size() == 1);
    EXPECT_EQ(again->robot_ids(0), "R2") << "the order went back to the robot out of service";
  }
  StopServer();

  StartServer();  // the mark is stored with the robot
  pb::RobotInfo info;
  ASSERT_TRUE(Call(&pb::OperatorService::Stub::ReturnToService, "R9", &info).error_code() ==
              grpc::StatusCode::NOT_FOUND);
  {
    OrderWatcher watcher(channel_);
    FakeRobot r1(channel_, "R1");
    r1.Connect(kP1x, kP1y);
    ASSERT_TRUE(r1.WaitFor(pb::ServerMessage::kWelcome));
    const std::string order = Submit("wms-2");
    httplib::Client rest("127.0.0.1", server_->ports().http);
    auto got = rest.Get("/api/v1/robots/R1");
    ASSERT_TRUE(got && got->status == 200);
    EXPECT_NE(got->body.find("\"out_of_service_by\":\"an operator\""), std::string::npos) << got->body;
    // R2 is offline (its stream ended with the old process): nobody may take the order yet.
    EXPECT_FALSE(r1.WaitFor(pb::ServerMessage::kAssignment, std::chrono::milliseconds(300)));
    auto returned = rest.Post("/api/v1/robots/R1/return-to-service", "", "application/json");
    ASSERT_TRUE(returned && returned->status == 200) << (returned ? returned->body : "no reply");
    EXPECT_NE(returned->body.find("\"out_of_service_by\":\"\""), std::string::npos) << returned->body;
    auto assigned = watcher.WaitForState(order, pb::ORDER_STATE_ASSIGNED);
    ASSERT_TRUE(assigned && assigned->robot_ids_size() == 1);
    EXPECT_EQ(assigned->robot_ids(0), "R1");
  }
}

TEST_F(RobotCommandsServiceTest, OnlyAnOfflineRobotIsClearedOffTheFloor) {
  StartServer();
  FakeRobot ghost(channel_, "G7");
  ghost.Connect(kP2x, kP2y);
  ASSERT_TRUE(ghost.WaitFor(pb::ServerMessage::kWelcome));
  pb::RobotInfo info;
  EXPECT_EQ(Call(&pb::OperatorService::Stub::ClearRobot, "G7", &info).error_code(),
            grpc::StatusCode::FAILED_PRECONDITION);
  ghost.Disconnect();
  const auto deadline = std::chrono::steady_clock::now() + kTimeout;
  grpc::Status cleared;
  do {  // the server notices the stream's end on its loop
    info.Clear();
    cleared = Call(&pb::OperatorService::Stub::ClearRobot, "G7", &info);
  } while (cleared.error_code() == grpc::StatusCode::FAILED_PRECONDITION && std::chrono::steady_clock::now() < deadline);
  ASSERT_TRUE(cleared.ok()) << cleared.error_message();
  EXPECT_TRUE(info.off_floor());
  EXPECT_FALSE(info.connected());
  // Back with a Hello: on the floor again.
  FakeRobot back(channel_, "G7");
  back.Connect(kP2x, kP2y);
  ASSERT_TRUE(back.WaitFor(pb::ServerMessage::kWelcome));
  httplib::Client rest("127.0.0.1", server_->ports().http);
  auto got = rest.Get("/api/v1/robots/G7");
  ASSERT_TRUE(got && got->status == 200);
  EXPECT_NE(got->body.find("\"off_floor\":false"), std::string::npos) << got->body;
}

TEST_F(RobotCommandsServiceTest, AnIdleRobotIsSentToAStation) {
  StartServer();
  FakeRobot r1(channel_, "R1");
  r1.Connect(kP1x, kP1y);
  ASSERT_TRUE(r1.WaitFor(pb::ServerMessage::kWelcome));
  pb::RobotInfo info;
  EXPECT_EQ(Send("R1", "nowhere", &info).error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(Send("R1", "K3-2-3N", &info).error_code(), grpc::StatusCode::INVALID_ARGUMENT) << "not a station";
  EXPECT_EQ(Send("R1", "", &info).error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  ASSERT_TRUE(Send("R1", "P4", &info).ok());
  EXPECT_EQ(info.sent_to().point_name(), "park-P4");
  auto plan = r1.WaitFor(pb::ServerMessage::kAssignment);
  ASSERT_TRUE(plan);
  const auto& waypoints = plan->assignment().waypoints();
  ASSERT_GE(waypoints.size(), 2);
  EXPECT_EQ(waypoints.rbegin()->point_id(), info.sent_to().point_id());
  EXPECT_EQ(waypoints.rbegin()->action(), pb::WAYPOINT_ACTION_PARK);
  EXPECT_EQ(plan->assignment().order_ids_size(), 0);
  // Over REST: the body is a SendRobotRequest; a busy station is refused.
  FakeRobot r2(channel_, "R2");
  r2.Connect(kP2x, kP2y);
  ASSERT_TRUE(r2.WaitFor(pb::ServerMessage::kWelcome));
  httplib::Client rest("127.0.0.1", server_->ports().http);
  auto busy = rest.Post("/api/v1/robots/R2/send", R"({"station": "P4"})", "application/json");
  ASSERT_TRUE(busy);
  EXPECT_EQ(busy->status, 409) << busy->body;
  auto sent = rest.Post("/api/v1/robots/R2/send", R"({"station": "P5"})", "application/json");
  ASSERT_TRUE(sent && sent->status == 200) << (sent ? sent->body : "no reply");
  EXPECT_NE(sent->body.find("park-P5"), std::string::npos) << sent->body;
  auto text = rest.Post("/api/v1/robots/R2/send", R"({"station": "P6"})", "text/plain");
  ASSERT_TRUE(text);
  EXPECT_EQ(text->status, 415);
}

}  // namespace
}  // namespace dispatch::server::testing
