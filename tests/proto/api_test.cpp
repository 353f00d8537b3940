// The generated API: messages survive the wire format, oneofs keep their case, and the
// services have the methods and streaming shapes the SPEC names (§4).
#include <gtest/gtest.h>

#include <google/protobuf/descriptor.h>

#include <string>
#include <vector>

#include "warehouse/dispatch/v1/fleet.grpc.pb.h"
#include "warehouse/dispatch/v1/fleet.pb.h"
#include "warehouse/dispatch/v1/map.grpc.pb.h"
#include "warehouse/dispatch/v1/map.pb.h"
#include "warehouse/dispatch/v1/orders.grpc.pb.h"
#include "warehouse/dispatch/v1/orders.pb.h"

namespace dispatch::proto {
namespace {

namespace v1 = ::warehouse::dispatch::v1;
using google::protobuf::DescriptorPool;
using google::protobuf::MethodDescriptor;
using google::protobuf::ServiceDescriptor;

template <class M>
M RoundTrip(const M& in) {
  std::string wire;
  EXPECT_TRUE(in.SerializeToString(&wire));
  M out;
  EXPECT_TRUE(out.ParseFromString(wire));
  return out;
}

TEST(ProtoApiTest, SubmitOrderRequestRoundTrips) {
  v1::SubmitOrderRequest req;
  req.set_client_order_id("wms-42");
  req.set_priority(3);
  req.add_picks()->set_point_name("P1-1-1");
  v1::Vec2* xy = req.add_picks()->mutable_position();
  xy->set_x(19.0);
  xy->set_y(16.5);
  req.mutable_drop()->set_point_name("D2");
  req.set_formation(true);
  req.set_work_time(7.5);

  const v1::SubmitOrderRequest out = RoundTrip(req);
  EXPECT_EQ(out.client_order_id(), "wms-42");
  EXPECT_EQ(out.priority(), 3);
  ASSERT_EQ(out.picks_size(), 2);
  EXPECT_EQ(out.picks(0).target_case(), v1::StopSpec::kPointName);
  EXPECT_EQ(out.picks(0).point_name(), "P1-1-1");
  EXPECT_EQ(out.picks(1).target_case(), v1::StopSpec::kPosition);
  EXPECT_DOUBLE_EQ(out.picks(1).position().y(), 16.5);
  EXPECT_EQ(out.drop().point_name(), "D2");
  EXPECT_TRUE(out.formation());
  ASSERT_TRUE(out.has_work_time());
  EXPECT_DOUBLE_EQ(out.work_time(), 7.5);
  EXPECT_FALSE(out.has_release_time());  // proto3 optional: absence survives the wire
  EXPECT_EQ(out.SerializeAsString(), req.SerializeAsString());
}

TEST(ProtoApiTest, ServerMessageKeepsSequenceAndOneofCase) {
  v1::ServerMessage msg;
  msg.set_sequence(17);
  msg.set_server_time(12.25);
  v1::Assignment* a = msg.mutable_assignment();
  a->set_plan_id(4);
  a->add_order_ids("o-1");
  for (int i = 0; i < 3; ++i) {
    v1::TimedWaypoint* w = a->add_waypoints();
    w->set_sequence(100 + static_cast<unsigned>(i));
    w->set_point_id(i);
    w->set_eta(1.5 * i);
    w->set_action(i == 2 ? v1::WAYPOINT_ACTION_PICK : v1::WAYPOINT_ACTION_MOVE);
    w->set_released(i < 2);
  }
  a->set_released_up_to_sequence(101);

  const v1::ServerMessage out = RoundTrip(msg);
  EXPECT_EQ(out.sequence(), 17u);
  ASSERT_EQ(out.body_case(), v1::ServerMessage::kAssignment);
  ASSERT_EQ(out.assignment().waypoints_size(), 3);
  EXPECT_EQ(out.assignment().waypoints(2).sequence(), 102u);
  EXPECT_EQ(out.assignment().waypoints(2).action(), v1::WAYPOINT_ACTION_PICK);
  EXPECT_FALSE(out.assignment().waypoints(2).released());
  EXPECT_EQ(out.assignment().released_up_to_sequence(), 101u);

  // Setting another body replaces the assignment (one body per message).
  v1::ServerMessage grant = out;
  grant.mutable_grant()->set_release_up_to_sequence(102);
  EXPECT_EQ(grant.body_case(), v1::ServerMessage::kGrant);
  EXPECT_FALSE(grant.has_assignment());
}

TEST(ProtoApiTest, RobotMessageHelloAndStateReportRoundTrip) {
  v1::RobotMessage hello;
  hello.mutable_hello()->set_robot_id("R7");
  hello.mutable_hello()->set_kind(v1::ROBOT_KIND_FOUR_WHEEL_STEER);
  hello.mutable_hello()->set_last_acked_sequence(41);
  hello.mutable_hello()->mutable_pose()->set_theta(1.5);
  const v1::RobotMessage h = RoundTrip(hello);
  ASSERT_EQ(h.body_case(), v1::RobotMessage::kHello);
  EXPECT_EQ(h.hello().robot_id(), "R7");
  EXPECT_EQ(h.hello().last_acked_sequence(), 41u);
  EXPECT_DOUBLE_EQ(h.hello().pose().theta(), 1.5);

  v1::RobotMessage report;
  report.mutable_state_report()->set_arc_id(0);  // arc 0 is a real arc, not "absent"
  report.mutable_state_report()->set_state(v1::ROBOT_STATE_WAITING);
  const v1::RobotMessage r = RoundTrip(report);
  ASSERT_EQ(r.body_case(), v1::RobotMessage::kStateReport);
  EXPECT_TRUE(r.state_report().has_arc_id());
  EXPECT_FALSE(r.state_report().has_battery());
  EXPECT_EQ(r.state_report().state(), v1::ROBOT_STATE_WAITING);
}

// Looked up through a message of the same file: a static library links only the generated
// files a program references, and only linked files are in the generated pool.
const ServiceDescriptor* FindService(const google::protobuf::Descriptor* message_in_file,
                                     const std::string& name) {
  const ServiceDescriptor* service = message_in_file->file()->FindServiceByName(name);
  if (service != nullptr) {
    EXPECT_EQ(service, DescriptorPool::generated_pool()->FindServiceByName(
                           "warehouse.dispatch.v1." + name));
  }
  return service;
}

struct MethodShape {
  std::string name;
  bool client_streaming;
  bool server_streaming;
};

void ExpectMethods(const ServiceDescriptor* service, const std::vector<MethodShape>& shapes) {
  ASSERT_NE(service, nullptr);
  EXPECT_EQ(service->method_count(), static_cast<int>(shapes.size())) << service->full_name();
  for (const MethodShape& shape : shapes) {
    const MethodDescriptor* m = service->FindMethodByName(shape.name);
    ASSERT_NE(m, nullptr) << service->full_name() << "." << shape.name;
    EXPECT_EQ(m->client_streaming(), shape.client_streaming) << shape.name;
    EXPECT_EQ(m->server_streaming(), shape.server_streaming) << shape.name;
  }
}

TEST(ProtoApiTest, ServicesHaveTheSpecifiedMethods) {
  ExpectMethods(FindService(v1::Order::descriptor(), "OrderService"),
                {{"SubmitOrder", false, false},
                 {"GetOrder", false, false},
                 {"CancelOrder", false, false},
                 {"ListOrders", false, false},
                 {"WatchOrders", false, true},
                 {"ExplainAllocation", false, false}});
  ExpectMethods(FindService(v1::RobotMessage::descriptor(), "FleetService"),
                {{"Connect", true, true}});
  ExpectMethods(FindService(v1::GetMapResponse::descriptor(), "MapService"),
                {{"GetMap", false, false}});
  // The generated gRPC stubs name the same services.
  EXPECT_STREQ(v1::OrderService::service_full_name(), "warehouse.dispatch.v1.OrderService");
  EXPECT_STREQ(v1::FleetService::service_full_name(), "warehouse.dispatch.v1.FleetService");
  EXPECT_STREQ(v1::MapService::service_full_name(), "warehouse.dispatch.v1.MapService");
}

TEST(ProtoApiTest, EveryServerBodyIsInTheOneof) {
  const auto* d = v1::ServerMessage::descriptor();
  ASSERT_NE(d->FindFieldByName("sequence"), nullptr);
  for (const char* body :
       {"welcome", "assignment", "plan_update", "grant", "hold", "resume", "cancel"}) {
    const auto* f = d->FindFieldByName(body);
    ASSERT_NE(f, nullptr) << body;
    ASSERT_NE(f->containing_oneof(), nullptr) << body;
    EXPECT_EQ(f->containing_oneof()->name(), "body") << body;
  }
  const auto* r = v1::RobotMessage::descriptor();
  for (const char* body :
       {"hello", "state_report", "waypoint_reached", "task_event", "heartbeat", "ack"}) {
    const auto* f = r->FindFieldByName(body);
    ASSERT_NE(f, nullptr) << body;
    EXPECT_NE(f->containing_oneof(), nullptr) << body;
  }
}

}  // namespace
}  // namespace dispatch::proto
