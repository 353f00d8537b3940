// Issue 15 §3b, memory stays bounded: finished orders beyond --finished-retained leave the
// dispatcher's memory and every door still finds them in the store (GetOrder, REST, the
// allocation explanation, ListOrders, WatchOrders, a repeated submission, a repeated cancel),
// with the counts and the order numbering intact across a restart.
// httplib.h comes after every header that pulls in Eigen (see STYLE.md on `_res`).
#include "tests/server/test_support.h"

#include <thread>

#include "server/dispatcher.h"

#include <httplib.h>
#include <nlohmann/json.hpp>

namespace dispatch::server::testing {
namespace {

using nlohmann::json;

constexpr double kP1x = 3.875, kP1y = -1.25;

class OrderRetentionTest : public ::testing::Test {
 protected:
  void StartServer() {
    auto started = DispatchServer::Start(config_);
    ASSERT_TRUE(started.ok()) << started.error().message;
    server_ = std::move(started).value();
    channel_ = ChannelTo(*server_);
    orders_ = pb::OrderService::NewStub(channel_);
    http_ = std::make_unique<httplib::Client>("127.0.0.1", server_->ports().http);
    http_->set_read_timeout(10, 0);
  }
  void StopServer() {
    http_.reset();
    orders_.reset();
    channel_.reset();
    server_.reset();
  }
  pb::SubmitOrderResponse Submit(const std::string& client, const std::string& drop = "D-B2") {
    grpc::ClientContext ctx;
    pb::SubmitOrderResponse r;
    EXPECT_TRUE(orders_->SubmitOrder(WithDeadline(ctx), OrderRequest(client, {"K3-2-3N"}, drop), &r).ok());
    return r;
  }
  grpc::Status Cancel(const std::string& id, pb::Order* out) {
    grpc::ClientContext ctx;
    pb::CancelOrderRequest request;
    request.set_order_id(id);
    request.set_reason("test " + id);
    return orders_->CancelOrder(WithDeadline(ctx), request, out);
  }
  grpc::Status Get(const std::string& id, pb::Order* out) {
    grpc::ClientContext ctx;
    pb::GetOrderRequest request;
    request.set_order_id(id);
    return orders_->GetOrder(WithDeadline(ctx), request, out);
  }
  std::vector<pb::Order> ListAll() {
    std::vector<pb::Order> out;
    std::string token;
    do {
      grpc::ClientContext ctx;
      pb::ListOrdersRequest request;
      request.set_page_size(2);
      request.set_page_token(token);
      pb::ListOrdersResponse page;
      EXPECT_TRUE(orders_->ListOrders(WithDeadline(ctx), request, &page).ok());
      out.insert(out.end(), page.orders().begin(), page.orders().end());
      token = page.next_page_token();
    } while (!token.empty());
    return out;
  }
  json RestGet(const std::string& path) {
    auto r = http_->Get(path);
    EXPECT_TRUE(r);
    if (!r) return json();
    EXPECT_EQ(r->status, 200) << path << ": " << r->body;
    return json::parse(r->body);
  }
  std::size_t InMemory() const { return server_->dispatcher().snapshot()->orders.size(); }

  TempDir dir_;
  ServerConfig config_ = [this] {
    ServerConfig c = TestConfig(dir_.File("retention.db"));
    c.time_scale = 50.0;
    c.finished_retained = 2;
    return c;
  }();
  std::unique_ptr<DispatchServer> server_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<pb::OrderService::Stub> orders_;
  std::unique_ptr<httplib::Client> http_;
};

TEST_F(OrderRetentionTest, FinishedOrdersBeyondTheRetentionAreReadFromTheStore) {
  StartServer();
  // One order served by a robot (so it has an explanation and a distance), then four
  // cancelled ones and one left open: the served one is the oldest finished.
  std::string served;
  {
    OrderWatcher watcher(channel_);
    FakeRobot robot(channel_, "R1");
    robot.Connect(kP1x, kP1y);
    ASSERT_TRUE(robot.WaitFor(pb::ServerMessage::kWelcome));
    served = Submit("served").order().id();
    auto assignment = robot.WaitFor(pb::ServerMessage::kAssignment);
    ASSERT_TRUE(assignment);
    ASSERT_GT(robot.Follow(assignment->assignment().waypoints(), assignment->assignment().released_up_to_sequence()), 0);
    ASSERT_TRUE(watcher.WaitForState(served, pb::ORDER_STATE_COMPLETED));
  }
  // R1's stream is closed: the orders below stay unallocated once the dispatcher saw it go.
  const auto deadline = std::chrono::steady_clock::now() + kTimeout;
  while (server_->dispatcher().snapshot()->robots.at("R1").connected) {
    ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "R1 never went offline";
    std::this_thread::yield();
  }
  std::vector<std::string> ids;
  for (int i = 0; i < 5; ++i) ids.push_back(Submit("c-" + std::to_string(i)).order().id());
  for (int i = 0; i < 4; ++i) {
    pb::Order cancelled;
    ASSERT_TRUE(Cancel(ids[static_cast<std::size_t>(i)], &cancelled).ok());
  }
  // In memory: the open order and the two finished last; 3 of the 5 finished are in the store only.
  EXPECT_EQ(InMemory(), 3u);
  EXPECT_FALSE(server_->dispatcher().snapshot()->FindOrder(served));
  EXPECT_FALSE(server_->dispatcher().snapshot()->FindOrder(ids[0]));

  pb::Order old;
  ASSERT_TRUE(Get(served, &old).ok());
  EXPECT_EQ(old.state(), pb::ORDER_STATE_COMPLETED);
  EXPECT_GT(old.distance(), 5.0);
  EXPECT_TRUE(old.has_finished_time());
  grpc::ClientContext ctx;
  pb::ExplainAllocationRequest explain;
  explain.set_order_id(served);
  pb::AllocationExplanation why;
  ASSERT_TRUE(orders_->ExplainAllocation(WithDeadline(ctx), explain, &why).ok());
  EXPECT_EQ(why.winner_ids(0), "R1");
  const json detail = RestGet("/api/v1/orders/" + served);
  EXPECT_EQ(detail["order"]["state"], "ORDER_STATE_COMPLETED");
  EXPECT_EQ(detail["allocation"]["winner_ids"][0], "R1");
  EXPECT_EQ(RestGet("/api/v1/orders/c-0")["order"]["reason"], "test " + ids[0]);  // by client id

  // Everything is listed and counted.
  const auto all = ListAll();
  ASSERT_EQ(all.size(), 6u);
  EXPECT_EQ(all[0].id(), served);
  EXPECT_EQ(all[1].state(), pb::ORDER_STATE_CANCELLED);
  const json status = RestGet("/api/v1/status");
  EXPECT_EQ(status["orders"]["completed"], 1);
  EXPECT_EQ(status["orders"]["cancelled"], 4);
  EXPECT_EQ(status["orders"]["accepted"], 1);
  const json list = RestGet("/api/v1/orders");
  EXPECT_EQ(list["finished_total"], 5);
  EXPECT_EQ(list["orders"].size(), 3u);

  // Repeats are answered as before: cancel, submit (same content: the stored order), watch.
  pb::Order again;
  ASSERT_TRUE(Cancel(ids[0], &again).ok());
  EXPECT_EQ(again.state(), pb::ORDER_STATE_CANCELLED);
  pb::Order refused;
  EXPECT_EQ(Cancel(served, &refused).error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  const pb::SubmitOrderResponse repeat = Submit("c-0");
  EXPECT_FALSE(repeat.created());
  EXPECT_EQ(repeat.order().id(), ids[0]);
  EXPECT_EQ(repeat.order().state(), pb::ORDER_STATE_CANCELLED);
  {
    grpc::ClientContext conflict_ctx;
    pb::SubmitOrderResponse r;
    EXPECT_EQ(orders_->SubmitOrder(WithDeadline(conflict_ctx), OrderRequest("c-0", {"K3-2-3N"}, "D-B1"), &r).error_code(),
              grpc::StatusCode::ALREADY_EXISTS);
  }
  pb::WatchOrdersRequest watch;
  watch.add_order_ids(ids[0]);
  watch.set_from_start(true);
  OrderWatcher replay(channel_, watch);
  EXPECT_TRUE(replay.WaitForState(ids[0], pb::ORDER_STATE_CANCELLED));
  EXPECT_EQ(InMemory(), 3u);  // none of that brought them back

  // A restart loads only what is kept, counts the rest and numbers on after the newest.
  StopServer();
  StartServer();
  EXPECT_EQ(InMemory(), 3u);
  EXPECT_EQ(RestGet("/api/v1/status")["orders"]["cancelled"], 4);
  ASSERT_TRUE(Get(served, &old).ok());
  EXPECT_GT(old.distance(), 5.0);  // stored with the completion
  EXPECT_EQ(Submit("after-restart").order().id(), "ord-000007");
}

}  // namespace
}  // namespace dispatch::server::testing
