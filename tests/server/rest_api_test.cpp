// REST basics through httplib::Client against an in-process server on 127.0.0.1.
// httplib.h comes after every header that pulls in Eigen (see STYLE.md on `_res`).
#include "tests/server/test_support.h"

#include <google/protobuf/util/json_util.h>
#include <google/protobuf/util/message_differencer.h>
#include <httplib.h>
#include <nlohmann/json.hpp>

#include "warehouse/dispatch/v1/operator.pb.h"

namespace dispatch::server::testing {
namespace {

using nlohmann::json;

class RestApiTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto started = DispatchServer::Start(TestConfig(dir_.File("rest.db")));
    ASSERT_TRUE(started.ok()) << started.error().message;
    server_ = std::move(started).value();
    client_ = std::make_unique<httplib::Client>("127.0.0.1", server_->ports().http);
    client_->set_read_timeout(10, 0);
  }

  json Body(const httplib::Result& r) {
    EXPECT_TRUE(r) << "no HTTP response";
    if (!r) return json();
    EXPECT_EQ(r->get_header_value("Content-Type"), "application/json");
    return json::parse(r->body);
  }

  TempDir dir_;
  std::unique_ptr<DispatchServer> server_;
  std::unique_ptr<httplib::Client> client_;
};

TEST_F(RestApiTest, HealthReadyAndStatus) {
  auto health = client_->Get("/healthz");
  ASSERT_TRUE(health);
  EXPECT_EQ(health->status, 200);
  auto ready = client_->Get("/readyz");
  ASSERT_TRUE(ready);
  EXPECT_EQ(ready->status, 200);
  EXPECT_TRUE(Body(ready)["ready"].get<bool>());
  auto status = client_->Get("/api/v1/status");
  ASSERT_TRUE(status);
  const json s = Body(status);
  EXPECT_EQ(s["map_name"], "chu2024");
  EXPECT_EQ(s["strategy"], "auction");
  EXPECT_EQ(s["orders"]["accepted"], 0);
  EXPECT_EQ(s["traffic"]["grants"], "0");  // uint64: a string in proto3 JSON
  EXPECT_FALSE(s["traffic"].contains("min_robot_distance"));  // no two robots seen yet
}

// Issue 15 §2: a REST body is the proto message's JSON mapping: what POST answers parses as a
// SubmitOrderResponse and equals what gRPC GetOrder returns for the same order.
TEST_F(RestApiTest, RestBodiesAreTheProtoMessagesJson) {
  auto created = client_->Post("/api/v1/orders",
                               R"({"client_order_id": "same-1", "picks": [{"point_name": "K3-2-3N"}],
                                   "drop": {"point_name": "D-B2"}, "priority": 2, "release_time": 30})",
                               "application/json");
  ASSERT_TRUE(created);
  ASSERT_EQ(created->status, 201) << created->body;
  pb::SubmitOrderResponse rest;
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(created->body, &rest).ok()) << created->body;
  EXPECT_TRUE(rest.created());
  auto stub = pb::OrderService::NewStub(ChannelTo(*server_));
  grpc::ClientContext ctx;
  pb::GetOrderRequest get;
  get.set_client_order_id("same-1");
  pb::Order grpc_order;
  ASSERT_TRUE(stub->GetOrder(WithDeadline(ctx), get, &grpc_order).ok());
  EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(rest.order(), grpc_order))
      << "REST: " << rest.order().DebugString() << "gRPC: " << grpc_order.DebugString();
  EXPECT_EQ(grpc_order.priority(), 2);
  EXPECT_EQ(grpc_order.release_time(), 30.0);
  // The detail and the list carry the same Order.
  pb::OrderDetail detail;
  auto one = client_->Get("/api/v1/orders/" + grpc_order.id());
  ASSERT_TRUE(one);
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(one->body, &detail).ok()) << one->body;
  EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(detail.order(), grpc_order));
  pb::OrderList list;
  auto all = client_->Get("/api/v1/orders");
  ASSERT_TRUE(all);
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(all->body, &list).ok()) << all->body;
  ASSERT_EQ(list.orders_size(), 1);
  EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(list.orders(0), grpc_order));
}

TEST_F(RestApiTest, OrdersThroughJson) {
  const std::string order =
      R"({"client_order_id": "rest-1", "picks": [{"point_name": "K3-2-3N"}], "drop": {"point_name": "D-B2"}})";
  auto created = client_->Post("/api/v1/orders", order, "application/json");
  ASSERT_TRUE(created);
  EXPECT_EQ(created->status, 201) << created->body;
  const json c = Body(created)["order"];
  const std::string id = c["id"];
  EXPECT_EQ(c["client_order_id"], "rest-1");
  EXPECT_EQ(c["state"], "ORDER_STATE_ACCEPTED");
  EXPECT_TRUE(c["robot_ids"].is_array());
  EXPECT_FALSE(c.contains("finished_time"));  // absent while open

  auto repeat = client_->Post("/api/v1/orders", order, "application/json");
  ASSERT_TRUE(repeat);
  EXPECT_EQ(repeat->status, 200);
  EXPECT_EQ(Body(repeat)["order"]["id"], id);
  EXPECT_FALSE(Body(repeat)["created"].get<bool>());

  auto conflict = client_->Post(
      "/api/v1/orders",
      R"({"client_order_id": "rest-1", "picks": [{"point_name": "K3-2-3N"}], "drop": {"point_name": "D-B1"}})",
      "application/json");
  ASSERT_TRUE(conflict);
  EXPECT_EQ(conflict->status, 409);
  EXPECT_NE(Body(conflict)["error"].get<std::string>().find(id), std::string::npos);

  auto coords = client_->Post("/api/v1/orders",
                              R"({"client_order_id": "rest-2", "picks": [{"position": {"x": 4, "y": 5}}],
                                  "drop": {"point_name": "D-B1"}})",
                              "application/json");
  ASSERT_TRUE(coords);
  EXPECT_EQ(coords->status, 201) << coords->body;
  EXPECT_EQ(Body(coords)["order"]["picks"][0]["point_name"], "K1-1-1N");

  auto list = client_->Get("/api/v1/orders");
  ASSERT_TRUE(list);
  const json l = Body(list);
  ASSERT_EQ(l["orders"].size(), 2u);
  EXPECT_EQ(l["orders"][0]["id"], id);
  EXPECT_EQ(l["orders"][0]["state"], "ORDER_STATE_ACCEPTED");

  auto one = client_->Get("/api/v1/orders/" + id);
  ASSERT_TRUE(one);
  EXPECT_EQ(one->status, 200);
  EXPECT_EQ(Body(one)["order"]["id"], id);
  EXPECT_FALSE(Body(one).contains("allocation"));  // not allocated (no robots)
  EXPECT_TRUE(Body(one)["routes"].empty());

  auto cancelled = client_->Delete("/api/v1/orders/" + id);
  ASSERT_TRUE(cancelled);
  EXPECT_EQ(cancelled->status, 200);
  EXPECT_EQ(Body(cancelled)["state"], "ORDER_STATE_CANCELLED");
  EXPECT_TRUE(Body(cancelled).contains("finished_time"));

  auto filtered = client_->Get("/api/v1/orders?state=cancelled");
  ASSERT_TRUE(filtered);
  ASSERT_EQ(Body(filtered)["orders"].size(), 1u);
  EXPECT_EQ(Body(filtered)["orders"][0]["id"], id);
  auto accepted = client_->Get("/api/v1/orders?state=accepted");
  ASSERT_TRUE(accepted);
  EXPECT_EQ(Body(accepted)["orders"].size(), 1u);
  auto by_enum = client_->Get("/api/v1/orders?state=ORDER_STATE_ACCEPTED");  // the enum's name too
  ASSERT_TRUE(by_enum);
  ASSERT_EQ(Body(by_enum)["orders"].size(), 1u);
  EXPECT_EQ(Body(by_enum)["orders"][0]["client_order_id"], "rest-2");
}

TEST_F(RestApiTest, TheOrderListKeepsOpenOrdersAndOnlyTheNewestFinishedOnes) {
  // Issue 15 §3b: the list held every order ever stored, and each HTTP thread's heap kept a
  // whole list's worth (140 kB per order with the web map polling).
  std::vector<std::string> ids;
  for (int i = 0; i < 5; ++i) {
    auto created = client_->Post("/api/v1/orders",
                                 R"({"client_order_id": "f-)" + std::to_string(i) +
                                     R"(", "picks": [{"point_name": "K3-2-3N"}], "drop": {"point_name": "D-B2"}})",
                                 "application/json");
    ASSERT_TRUE(created);
    ASSERT_EQ(created->status, 201) << created->body;
    ids.push_back(Body(created)["order"]["id"]);
  }
  for (int i = 0; i < 4; ++i) ASSERT_EQ(client_->Delete("/api/v1/orders/" + ids[static_cast<std::size_t>(i)])->status, 200);
  auto two = client_->Get("/api/v1/orders?finished=2");
  ASSERT_TRUE(two);
  const json l = Body(two);
  EXPECT_EQ(l["finished_total"], 4);
  ASSERT_EQ(l["orders"].size(), 3u);  // the open one and the two cancelled last
  EXPECT_EQ(l["orders"][0]["id"], ids[2]);  // in submission order
  EXPECT_EQ(l["orders"][1]["id"], ids[3]);
  EXPECT_EQ(l["orders"][2]["id"], ids[4]);
  EXPECT_EQ(l["orders"][2]["state"], "ORDER_STATE_ACCEPTED");
  const json none = Body(client_->Get("/api/v1/orders?finished=0"));
  ASSERT_EQ(none["orders"].size(), 1u);
  EXPECT_EQ(none["finished_total"], 4);
  EXPECT_EQ(Body(client_->Get("/api/v1/orders"))["orders"].size(), 5u);  // 100 by default
  EXPECT_EQ(Body(client_->Get("/api/v1/orders?state=cancelled&finished=1"))["orders"][0]["id"], ids[3]);
  for (const char* bad : {"-1", "abc", "1001", "", "99999"}) {
    auto r = client_->Get(std::string("/api/v1/orders?finished=") + bad);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 400) << bad;
    EXPECT_EQ(Body(r)["error"], "finished must be a whole number from 0 to 1000") << bad;
  }
}

TEST_F(RestApiTest, ErrorsAreJsonWithAReason) {
  struct Case {
    httplib::Result result;
    int status;
  };
  std::vector<Case> cases;
  cases.push_back({client_->Post("/api/v1/orders", "{not json", "application/json"), 400});
  const std::string stops = R"("picks": [{"point_name": "K3-2-3N"}], "drop": {"point_name": "D-B1"})";
  cases.push_back({client_->Post("/api/v1/orders",
                                 R"({"client_order_id": "x", "picks": [{"point_name": "NOPE"}], "drop": {"point_name": "D-B1"}})",
                                 "application/json"),
                   400});
  cases.push_back({client_->Post("/api/v1/orders", "{" + stops + "}", "application/json"), 400});
  // A misspelt field is named, not dropped (the order would have been released at once).
  cases.push_back({client_->Post("/api/v1/orders", R"({"client_order_id": "y", "relase_time": 60, )" + stops + "}",
                                 "application/json"),
                   400});
  cases.push_back({client_->Post("/api/v1/orders", R"({"client_order_id": "z", "release_time": 1e300, )" + stops + "}",
                                 "application/json"),
                   400});
  cases.push_back({client_->Get("/api/v1/orders/ord-424242"), 404});
  cases.push_back({client_->Delete("/api/v1/orders/ord-424242"), 404});
  cases.push_back({client_->Get("/api/v1/orders?state=sleeping"), 400});
  cases.push_back({client_->Get("/api/v1/robots/R99"), 404});
  cases.push_back({client_->Get("/api/v1/nothing-here"), 404});
  for (auto& c : cases) {
    ASSERT_TRUE(c.result);
    EXPECT_EQ(c.result->status, c.status) << c.result->body;
    const json body = json::parse(c.result->body);
    ASSERT_TRUE(body.contains("error")) << c.result->body;
    EXPECT_FALSE(body["error"].get<std::string>().empty());
  }
  EXPECT_NE(json::parse(cases[3].result->body)["error"].get<std::string>().find("relase_time"), std::string::npos);
  EXPECT_NE(json::parse(cases[4].result->body)["error"].get<std::string>().find("release time"), std::string::npos);
}

TEST_F(RestApiTest, RobotsAppearWhenTheyConnect) {
  auto empty = client_->Get("/api/v1/robots");
  ASSERT_TRUE(empty);
  EXPECT_TRUE(Body(empty)["robots"].empty());
  auto channel = ChannelTo(*server_);
  FakeRobot robot(channel, "R7");
  robot.Connect(3.875, -1.25);
  ASSERT_TRUE(robot.WaitFor(pb::ServerMessage::kWelcome));
  // The loop sends the Welcome only after publishing the snapshot that holds the robot.
  auto got = client_->Get("/api/v1/robots/R7");
  ASSERT_TRUE(got);
  ASSERT_EQ(got->status, 200) << got->body;
  const json r = Body(got);
  EXPECT_EQ(r["id"], "R7");
  EXPECT_TRUE(r["connected"].get<bool>());
  EXPECT_EQ(r["point"]["point_name"], "park-P1");
  EXPECT_EQ(r["state"], "ROBOT_STATE_IDLE");
  EXPECT_EQ(r["pose"]["x"], 3.875);
  auto all = client_->Get("/api/v1/robots");
  ASSERT_TRUE(all);
  EXPECT_EQ(Body(all)["robots"].size(), 1u);
}

}  // namespace
}  // namespace dispatch::server::testing
