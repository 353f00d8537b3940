// The server end to end over real gRPC on 127.0.0.1: orders through their lifecycle with a
// fake robot, idempotency, conflicting duplicates, bad inputs, cancel, restart on the same
// database, and store failures reaching the caller.
#include <gtest/gtest.h>

#include "server/dispatcher.h"
#include "storage/fault_injection_store.h"
#include "storage/sqlite_store.h"
#include "tests/server/test_support.h"

namespace dispatch::server::testing {
namespace {

// park-P1 and park-P2 of the Chu2024 floor (robots R1, R2 start there).
constexpr double kP1x = 3.875, kP1y = -1.25;
constexpr double kP2x = 9.75, kP2y = -1.25;

class OrderFlowTest : public ::testing::Test {
 protected:
  void StartServer(storage::Store* store = nullptr) {
    auto started = DispatchServer::Start(config_, store);
    ASSERT_TRUE(started.ok()) << started.error().message;
    server_ = std::move(started).value();
    channel_ = ChannelTo(*server_);
    orders_ = pb::OrderService::NewStub(channel_);
  }
  void StopServer() {
    orders_.reset();
    channel_.reset();
    server_.reset();
  }

  grpc::Status Submit(const pb::SubmitOrderRequest& request, pb::SubmitOrderResponse* response) {
    grpc::ClientContext ctx;
    return orders_->SubmitOrder(WithDeadline(ctx), request, response);
  }
  pb::Order Get(const std::string& id) {
    grpc::ClientContext ctx;
    pb::GetOrderRequest request;
    request.set_order_id(id);
    pb::Order order;
    EXPECT_TRUE(orders_->GetOrder(WithDeadline(ctx), request, &order).ok());
    return order;
  }
  pb::ListOrdersResponse List(std::vector<pb::OrderState> states = {}, int page_size = 0,
                              const std::string& token = "") {
    grpc::ClientContext ctx;
    pb::ListOrdersRequest request;
    for (auto s : states) request.add_states(s);
    request.set_page_size(page_size);
    request.set_page_token(token);
    pb::ListOrdersResponse response;
    EXPECT_TRUE(orders_->ListOrders(WithDeadline(ctx), request, &response).ok());
    return response;
  }

  TempDir dir_;
  ServerConfig config_ = [this] {
    ServerConfig c = TestConfig(dir_.File("dispatch.db"));
    c.time_scale = 50.0;  // the fake robot waits for the plan's times between releases
    return c;
  }();
  std::unique_ptr<DispatchServer> server_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<pb::OrderService::Stub> orders_;
};

TEST_F(OrderFlowTest, SubmitAssignCompleteWithARobot) {
  StartServer();
  OrderWatcher watcher(channel_);
  FakeRobot robot(channel_, "R1");
  robot.Connect(kP1x, kP1y);
  auto welcome = robot.WaitFor(pb::ServerMessage::kWelcome);
  ASSERT_TRUE(welcome);
  EXPECT_DOUBLE_EQ(welcome->welcome().time_scale(), 50.0);
  EXPECT_FALSE(welcome->welcome().map_version().empty());

  pb::SubmitOrderResponse submitted;
  ASSERT_TRUE(Submit(OrderRequest("wms-1", {"K3-2-3N"}, "D-B2"), &submitted).ok());
  EXPECT_TRUE(submitted.created());
  const std::string id = submitted.order().id();
  EXPECT_EQ(submitted.order().picks(0).point_name(), "K3-2-3N");

  auto assigned = watcher.WaitForState(id, pb::ORDER_STATE_ASSIGNED);
  ASSERT_TRUE(assigned) << "no assigned event";
  ASSERT_EQ(assigned->robot_ids_size(), 1);
  EXPECT_EQ(assigned->robot_ids(0), "R1");

  auto assignment = robot.WaitFor(pb::ServerMessage::kAssignment);
  ASSERT_TRUE(assignment);
  const auto& plan = assignment->assignment();
  ASSERT_EQ(plan.order_ids_size(), 1);
  EXPECT_EQ(plan.order_ids(0), id);
  ASSERT_GE(plan.waypoints_size(), 3);
  int picks = 0, drops = 0;
  // Traffic control: only what lies at the robot's point is released; Grants release the rest.
  EXPECT_LT(plan.released_up_to_sequence(), plan.waypoints(plan.waypoints_size() - 1).sequence());
  for (int i = 0; i < plan.waypoints_size(); ++i) {
    const auto& w = plan.waypoints(i);
    EXPECT_EQ(w.released(), w.sequence() <= plan.released_up_to_sequence());
    if (i > 0) {
      EXPECT_EQ(w.sequence(), plan.waypoints(i - 1).sequence() + 1);
      EXPECT_GE(w.eta(), plan.waypoints(i - 1).eta());
    }
    picks += w.action() == pb::WAYPOINT_ACTION_PICK;
    drops += w.action() == pb::WAYPOINT_ACTION_DROP;
  }
  EXPECT_EQ(picks, 1);
  EXPECT_EQ(drops, 1);
  EXPECT_EQ(plan.waypoints(plan.waypoints_size() - 1).action(), pb::WAYPOINT_ACTION_DROP);

  // Point by point: a Grant per point the robot may drive on to (a robot that reports
  // arriving early waits for the plan's times, which run 50x faster here).
  const int grants = robot.Follow(plan.waypoints(), plan.released_up_to_sequence());
  EXPECT_GT(grants, 3) << "no releases came";
  ASSERT_TRUE(watcher.WaitForState(id, pb::ORDER_STATE_IN_PROGRESS));
  auto completed = watcher.WaitForState(id, pb::ORDER_STATE_COMPLETED);
  ASSERT_TRUE(completed);

  const pb::Order order = Get(id);
  EXPECT_EQ(order.state(), pb::ORDER_STATE_COMPLETED);
  ASSERT_EQ(order.robot_ids_size(), 1);
  EXPECT_EQ(order.robot_ids(0), "R1");
  EXPECT_TRUE(order.has_finished_time());

  grpc::ClientContext ctx;
  pb::ExplainAllocationRequest explain;
  explain.set_order_id(id);
  pb::AllocationExplanation explanation;
  ASSERT_TRUE(orders_->ExplainAllocation(WithDeadline(ctx), explain, &explanation).ok());
  EXPECT_EQ(explanation.strategy(), "auction");
  ASSERT_EQ(explanation.bids_size(), 1);
  EXPECT_EQ(explanation.bids_total(), 1u);
  EXPECT_EQ(explanation.bids(0).robot_id(), "R1");
  EXPECT_TRUE(explanation.bids(0).winner());
  EXPECT_GT(explanation.bids(0).total(), 0.0);
  ASSERT_EQ(explanation.winner_ids_size(), 1);
  EXPECT_DOUBLE_EQ(explanation.zeta(), 100.0);

  // A late watcher replays the order's whole journal from the start.
  pb::WatchOrdersRequest replay;
  replay.set_from_start(true);
  replay.add_order_ids(id);
  OrderWatcher late(channel_, replay);
  std::vector<pb::OrderState> states;
  std::uint64_t last_event = 0;
  while (states.empty() || states.back() != pb::ORDER_STATE_COMPLETED) {
    auto e = late.Next();
    ASSERT_TRUE(e) << "journal replay ended early";
    EXPECT_EQ(e->order_id(), id);
    EXPECT_GT(e->event_id(), last_event);
    last_event = e->event_id();
    if (e->type() != pb::ORDER_EVENT_TYPE_PROGRESS) states.push_back(e->state());
  }
  EXPECT_EQ(states, (std::vector<pb::OrderState>{pb::ORDER_STATE_ACCEPTED, pb::ORDER_STATE_ASSIGNED,
                                                 pb::ORDER_STATE_IN_PROGRESS, pb::ORDER_STATE_COMPLETED}));
}

TEST_F(OrderFlowTest, RegressionAPickOrDropIsTakenOnlyWhereTheRobotStands) {
  // Issue 15 §3b: a client that said Hello as an unknown robot id received an order and
  // reported it completed without driving (distance 0.0). Now a drop counts only once the robot
  // has reached that order's drop waypoint (released to it, the pose near it) and stands there.
  StartServer();
  OrderWatcher watcher(channel_);
  FakeRobot robot(channel_, "Liar1");
  robot.Connect(kP1x, kP1y);
  ASSERT_TRUE(robot.WaitFor(pb::ServerMessage::kWelcome));
  pb::SubmitOrderResponse submitted;
  ASSERT_TRUE(Submit(OrderRequest("wms-liar", {"K3-2-3N"}, "D-B2"), &submitted).ok());
  const std::string id = submitted.order().id();
  auto assignment = robot.WaitFor(pb::ServerMessage::kAssignment);
  ASSERT_TRUE(assignment);
  const auto& plan = assignment->assignment();
  const auto& drop = plan.waypoints(plan.waypoints_size() - 1);
  ASSERT_EQ(drop.action(), pb::WAYPOINT_ACTION_DROP);
  ASSERT_GT(drop.sequence(), plan.released_up_to_sequence());
  // Straight to the drop: an arrival at a waypoint not released, then picked and dropped events
  // while it stands at its station (they wait until it has reached the stops: a drop repeated
  // after a restart comes before the robot's first progress report).
  pb::RobotMessage reached;
  reached.mutable_waypoint_reached()->set_sequence(drop.sequence());
  reached.mutable_waypoint_reached()->mutable_pose()->set_x(drop.x());
  reached.mutable_waypoint_reached()->mutable_pose()->set_y(drop.y());
  ASSERT_TRUE(robot.Write(reached));
  for (const auto type : {pb::TASK_EVENT_TYPE_PICKED, pb::TASK_EVENT_TYPE_DROPPED}) {
    pb::RobotMessage event;
    event.mutable_task_event()->set_order_id(id);
    event.mutable_task_event()->set_type(type);
    event.mutable_task_event()->set_point_id(drop.point_id());
    event.mutable_task_event()->set_waypoint_sequence(drop.sequence());
    ASSERT_TRUE(robot.Write(event));
  }
  // An arrival far from its waypoint is not taken either.
  pb::RobotMessage far;
  far.mutable_waypoint_reached()->set_sequence(plan.waypoints(0).sequence());
  far.mutable_waypoint_reached()->mutable_pose()->set_x(drop.x());
  far.mutable_waypoint_reached()->mutable_pose()->set_y(drop.y());
  ASSERT_TRUE(robot.Write(far));
  // Then it drives the plan for real: the order completes, with the distance driven.
  ASSERT_GT(robot.Follow(plan.waypoints(), plan.released_up_to_sequence()), 0);
  ASSERT_TRUE(watcher.WaitForState(id, pb::ORDER_STATE_COMPLETED));
  const pb::Order order = Get(id);
  EXPECT_GT(order.distance(), 5.0);
  // Stored with the completion: ListOrders reads the store, and a restart keeps it.
  EXPECT_DOUBLE_EQ(List().orders(0).distance(), order.distance());
  // The forged arrivals were processed before the real reports (one stream, in order) and
  // flagged; the early picked / dropped events counted only once it had reached the stops.
  EXPECT_EQ(server_->dispatcher().snapshot()->traffic.implausible_reports, 2u);
}

TEST_F(OrderFlowTest, WatchingAnUnknownOrderIsNotFound) {
  StartServer();
  pb::SubmitOrderResponse a;
  ASSERT_TRUE(Submit(OrderRequest("known", {"K1-1-1N"}, "D-B1"), &a).ok());
  pb::WatchOrdersRequest request;
  request.add_order_ids(a.order().id());
  request.add_order_ids("ord-999999");
  grpc::ClientContext ctx;
  auto reader = orders_->WatchOrders(WithDeadline(ctx), request);
  pb::OrderEvent e;
  EXPECT_FALSE(reader->Read(&e));  // refused at once, not left waiting
  const grpc::Status s = reader->Finish();
  EXPECT_EQ(s.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_NE(s.error_message().find("ord-999999"), std::string::npos) << s.error_message();
  // The known order alone is watched as before: its journal replays from the start.
  pb::WatchOrdersRequest known;
  known.set_from_start(true);
  known.add_order_ids(a.order().id());
  OrderWatcher watcher(channel_, known);
  auto accepted = watcher.WaitForState(a.order().id(), pb::ORDER_STATE_ACCEPTED);
  ASSERT_TRUE(accepted);
}

TEST_F(OrderFlowTest, EveryConnectedRobotBidsAndTheLowestBidWins) {
  StartServer();
  OrderWatcher watcher(channel_);
  FakeRobot r1(channel_, "R1"), r2(channel_, "R2");
  r1.Connect(kP1x, kP1y);
  r2.Connect(kP2x, kP2y);
  ASSERT_TRUE(r1.WaitFor(pb::ServerMessage::kWelcome));
  ASSERT_TRUE(r2.WaitFor(pb::ServerMessage::kWelcome));
  // K1-1-1N (4, 5) is next to park-P1; the auction gives it to R1.
  pb::SubmitOrderResponse a;
  ASSERT_TRUE(Submit(OrderRequest("near-R1", {"K1-1-1N"}, "D-B1"), &a).ok());
  auto assigned = watcher.WaitForState(a.order().id(), pb::ORDER_STATE_ASSIGNED);
  ASSERT_TRUE(assigned);
  EXPECT_EQ(assigned->robot_ids(0), "R1");
  // Far from both parking stations: whoever wins, its bid is the lowest of both robots'
  // (R1's counts its queue, Chu2024 eq. 3).
  pb::SubmitOrderResponse b;
  ASSERT_TRUE(Submit(OrderRequest("second", {"K3-6-1N"}, "D-R1"), &b).ok());
  auto assigned_b = watcher.WaitForState(b.order().id(), pb::ORDER_STATE_ASSIGNED);
  ASSERT_TRUE(assigned_b);
  grpc::ClientContext ctx;
  pb::ExplainAllocationRequest explain;
  explain.set_order_id(b.order().id());
  pb::AllocationExplanation why;
  ASSERT_TRUE(orders_->ExplainAllocation(WithDeadline(ctx), explain, &why).ok());
  ASSERT_EQ(why.bids_size(), 2);
  EXPECT_EQ(why.bids(0).robot_id(), "R1");
  EXPECT_EQ(why.bids(1).robot_id(), "R2");
  const auto& best = why.bids(0).total() <= why.bids(1).total() ? why.bids(0) : why.bids(1);
  EXPECT_EQ(assigned_b->robot_ids(0), best.robot_id());
  EXPECT_TRUE(best.winner());
  // R1's bid counts the order already in its queue (Chu2024 eq. 3: n_c over the whole
  // queue, t_w = 5 s per pick, and by default t_w at each drop too): 2 picks and 2 drops
  // against R2's 1 and 1.
  EXPECT_DOUBLE_EQ(why.bids(0).work_time(), 20.0);
  EXPECT_DOUBLE_EQ(why.bids(1).work_time(), 10.0);
}

// A batch window (--batch-window) with a batch strategy: the first order is allocated at once;
// the two submitted next wait for the window's end and are allocated together, one exact
// assignment over both.
TEST_F(OrderFlowTest, ABatchWindowAllocatesTheOrdersArrivingInItTogether) {
  config_.time_scale = 1.0;
  config_.strategy = "exact";
  config_.batch_window = 2.0;
  StartServer();
  OrderWatcher watcher(channel_);
  FakeRobot r1(channel_, "R1"), r2(channel_, "R2");
  r1.Connect(kP1x, kP1y);
  r2.Connect(kP2x, kP2y);
  ASSERT_TRUE(r1.WaitFor(pb::ServerMessage::kWelcome));
  ASSERT_TRUE(r2.WaitFor(pb::ServerMessage::kWelcome));
  auto explain = [&](const std::string& id) {
    grpc::ClientContext ctx;
    pb::ExplainAllocationRequest request;
    request.set_order_id(id);
    pb::AllocationExplanation why;
    EXPECT_TRUE(orders_->ExplainAllocation(WithDeadline(ctx), request, &why).ok());
    return why;
  };
  pb::SubmitOrderResponse first, b, c;
  ASSERT_TRUE(Submit(OrderRequest("first", {"K1-1-1N"}, "D-B1"), &first).ok());
  ASSERT_TRUE(watcher.WaitForState(first.order().id(), pb::ORDER_STATE_ASSIGNED));
  ASSERT_TRUE(Submit(OrderRequest("b", {"K3-6-1N"}, "D-R1"), &b).ok());
  ASSERT_TRUE(Submit(OrderRequest("c", {"K3-2-3N"}, "D-B2"), &c).ok());
  ASSERT_TRUE(watcher.WaitForState(b.order().id(), pb::ORDER_STATE_ASSIGNED));
  ASSERT_TRUE(watcher.WaitForState(c.order().id(), pb::ORDER_STATE_ASSIGNED));
  const pb::AllocationExplanation why_first = explain(first.order().id());
  const pb::AllocationExplanation why_b = explain(b.order().id());
  const pb::AllocationExplanation why_c = explain(c.order().id());
  EXPECT_EQ(why_first.strategy(), "exact");
  EXPECT_EQ(why_first.reason().rfind("exact over 1 orders", 0), 0u) << why_first.reason();
  EXPECT_EQ(why_b.reason().rfind("exact over 2 orders", 0), 0u) << why_b.reason();
  EXPECT_EQ(why_c.reason().rfind("exact over 2 orders", 0), 0u) << why_c.reason();
  EXPECT_DOUBLE_EQ(why_b.time(), why_c.time());  // one round
  EXPECT_GE(why_b.time() - why_first.time(), 2.0 - 1e-6);  // not before the window ended
}

TEST_F(OrderFlowTest, OrdersWaitAcceptedUntilARobotConnects) {
  StartServer();
  OrderWatcher watcher(channel_);
  pb::SubmitOrderResponse submitted;
  ASSERT_TRUE(Submit(OrderRequest("early", {"K3-2-3N"}, "D-B2"), &submitted).ok());
  EXPECT_EQ(submitted.order().state(), pb::ORDER_STATE_ACCEPTED);
  EXPECT_EQ(Get(submitted.order().id()).state(), pb::ORDER_STATE_ACCEPTED);
  FakeRobot robot(channel_, "R1");
  robot.Connect(kP1x, kP1y);
  auto assigned = watcher.WaitForState(submitted.order().id(), pb::ORDER_STATE_ASSIGNED);
  ASSERT_TRUE(assigned);
  EXPECT_EQ(assigned->robot_ids(0), "R1");
  ASSERT_TRUE(robot.WaitFor(pb::ServerMessage::kAssignment));
}

TEST_F(OrderFlowTest, ResubmittingTheSameOrderReturnsTheSameOrder) {
  StartServer();
  pb::SubmitOrderResponse first, second, by_coordinate;
  ASSERT_TRUE(Submit(OrderRequest("dup-1", {"K3-2-3N"}, "D-B2"), &first).ok());
  ASSERT_TRUE(Submit(OrderRequest("dup-1", {"K3-2-3N"}, "D-B2"), &second).ok());
  EXPECT_TRUE(first.created());
  EXPECT_FALSE(second.created());
  EXPECT_EQ(first.order().id(), second.order().id());
  // The same stop given as a coordinate is the same content.
  pb::SubmitOrderRequest coords = OrderRequest("dup-1", {}, "D-B2");
  coords.add_picks()->mutable_position()->set_x(10.5);
  coords.mutable_picks(0)->mutable_position()->set_y(13.0);
  ASSERT_TRUE(Submit(coords, &by_coordinate).ok());
  EXPECT_FALSE(by_coordinate.created());
  EXPECT_EQ(by_coordinate.order().id(), first.order().id());
  EXPECT_EQ(List().orders_size(), 1);
}

TEST_F(OrderFlowTest, ConflictingDuplicateIsAlreadyExistsNamingBoth) {
  StartServer();
  pb::SubmitOrderResponse first, second;
  ASSERT_TRUE(Submit(OrderRequest("dup-2", {"K3-2-3N"}, "D-B2"), &first).ok());
  const grpc::Status status = Submit(OrderRequest("dup-2", {"K3-2-3N"}, "D-B1"), &second);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::ALREADY_EXISTS);
  EXPECT_NE(status.error_message().find("dup-2"), std::string::npos) << status.error_message();
  EXPECT_NE(status.error_message().find(first.order().id()), std::string::npos) << status.error_message();
  EXPECT_EQ(List().orders_size(), 1);
}

TEST_F(OrderFlowTest, BadOrdersGetInvalidArgumentWithAClearMessage) {
  StartServer();
  struct Case {
    pb::SubmitOrderRequest request;
    std::string expect_in_message;
  };
  std::vector<Case> cases;
  cases.push_back({OrderRequest("bad-1", {"NOPE"}, "D-B2"), "NOPE"});
  cases.push_back({OrderRequest("bad-2", {}, "D-B2"), "pick"});
  cases.push_back({OrderRequest("", {"K3-2-3N"}, "D-B2"), "client_order_id"});
  cases.push_back({OrderRequest("bad-4", {"K3-2-3N"}, "K3-2-2N"), "K3-2-2N"});  // a pick as drop
  pb::SubmitOrderRequest no_drop = OrderRequest("bad-5", {"K3-2-3N"}, "D-B2");
  no_drop.clear_drop();
  cases.push_back({no_drop, "drop"});
  pb::SubmitOrderRequest off_map = OrderRequest("bad-6", {}, "D-B2");
  off_map.add_picks()->mutable_position()->set_x(500.0);
  cases.push_back({off_map, "500"});
  pb::SubmitOrderRequest bad_work = OrderRequest("bad-7", {"K3-2-3N"}, "D-B2");
  bad_work.set_work_time(-1.0);
  cases.push_back({bad_work, "work"});
  pb::SubmitOrderRequest lane_heading = OrderRequest("bad-8", {"K3-2-3N"}, "D-B2");
  lane_heading.mutable_picks(0)->set_heading(1.0);  // the Chu2024 floor has no free space
  cases.push_back({lane_heading, "a heading can only be given at a point inside a free-space region"});
  for (const auto& c : cases) {
    pb::SubmitOrderResponse response;
    const grpc::Status status = Submit(c.request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << c.request.DebugString();
    EXPECT_NE(status.error_message().find(c.expect_in_message), std::string::npos)
        << "message '" << status.error_message() << "' should mention '" << c.expect_in_message << "'";
  }
  EXPECT_EQ(List().orders_size(), 0);

  grpc::ClientContext ctx;
  pb::GetOrderRequest get;
  get.set_order_id("ord-999999");
  pb::Order order;
  EXPECT_EQ(orders_->GetOrder(WithDeadline(ctx), get, &order).error_code(), grpc::StatusCode::NOT_FOUND);
}

TEST_F(OrderFlowTest, BadRobotStreamsAreRejected) {
  StartServer();
  FakeRobot off_map(channel_, "R1");
  off_map.Connect(500.0, 500.0);
  grpc::Status status = off_map.AwaitEnd();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(status.error_message().find("not on the map"), std::string::npos) << status.error_message();

  FakeRobot bad_id(channel_, "R 1!");
  bad_id.Connect(kP1x, kP1y);
  status = bad_id.AwaitEnd();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(status.error_message().find("robot id"), std::string::npos) << status.error_message();

  // A live robot id cannot be taken over by a second stream.
  FakeRobot first(channel_, "R2"), second(channel_, "R2");
  first.Connect(kP2x, kP2y);
  ASSERT_TRUE(first.WaitFor(pb::ServerMessage::kWelcome));
  second.Connect(kP2x, kP2y);
  status = second.AwaitEnd();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::ALREADY_EXISTS);
}

TEST_F(OrderFlowTest, CancelTellsTheRobotAndFreesIt) {
  StartServer();
  OrderWatcher watcher(channel_);
  FakeRobot robot(channel_, "R1");
  robot.Connect(kP1x, kP1y);
  pb::SubmitOrderResponse submitted;
  ASSERT_TRUE(Submit(OrderRequest("to-cancel", {"K3-2-3N"}, "D-B2"), &submitted).ok());
  const std::string id = submitted.order().id();
  ASSERT_TRUE(watcher.WaitForState(id, pb::ORDER_STATE_ASSIGNED));
  ASSERT_TRUE(robot.WaitFor(pb::ServerMessage::kAssignment));

  grpc::ClientContext ctx;
  pb::CancelOrderRequest cancel;
  cancel.set_order_id(id);
  cancel.set_reason("customer changed their mind");
  pb::Order cancelled;
  ASSERT_TRUE(orders_->CancelOrder(WithDeadline(ctx), cancel, &cancelled).ok());
  EXPECT_EQ(cancelled.state(), pb::ORDER_STATE_CANCELLED);
  EXPECT_EQ(cancelled.reason(), "customer changed their mind");
  auto message = robot.WaitFor(pb::ServerMessage::kCancel);
  ASSERT_TRUE(message);
  ASSERT_EQ(message->cancel().order_ids_size(), 1);
  EXPECT_EQ(message->cancel().order_ids(0), id);

  grpc::ClientContext again;
  pb::Order unchanged;
  ASSERT_TRUE(orders_->CancelOrder(WithDeadline(again), cancel, &unchanged).ok());
  EXPECT_EQ(unchanged.state(), pb::ORDER_STATE_CANCELLED);

  // The freed robot takes the next order with a fresh plan.
  pb::SubmitOrderResponse next;
  ASSERT_TRUE(Submit(OrderRequest("after-cancel", {"K1-1-1N"}, "D-B1"), &next).ok());
  ASSERT_TRUE(watcher.WaitForState(next.order().id(), pb::ORDER_STATE_ASSIGNED));
  auto assignment = robot.WaitFor(pb::ServerMessage::kAssignment);
  ASSERT_TRUE(assignment);
  EXPECT_EQ(assignment->assignment().order_ids(0), next.order().id());
}

TEST_F(OrderFlowTest, ListOrdersFiltersAndPages) {
  StartServer();
  std::vector<std::string> ids;
  for (int i = 0; i < 5; ++i) {
    pb::SubmitOrderResponse r;
    ASSERT_TRUE(Submit(OrderRequest("page-" + std::to_string(i), {"K3-2-3N"}, "D-B2"), &r).ok());
    ids.push_back(r.order().id());
  }
  grpc::ClientContext ctx;
  pb::CancelOrderRequest cancel;
  cancel.set_order_id(ids[1]);
  pb::Order cancelled;
  ASSERT_TRUE(orders_->CancelOrder(WithDeadline(ctx), cancel, &cancelled).ok());

  std::vector<std::string> seen;
  std::string token;
  do {
    auto page = List({}, 2, token);
    EXPECT_LE(page.orders_size(), 2);
    for (const auto& o : page.orders()) seen.push_back(o.id());
    token = page.next_page_token();
  } while (!token.empty());
  EXPECT_EQ(seen, ids);
  auto accepted = List({pb::ORDER_STATE_ACCEPTED});
  EXPECT_EQ(accepted.orders_size(), 4);
  auto only_cancelled = List({pb::ORDER_STATE_CANCELLED});
  ASSERT_EQ(only_cancelled.orders_size(), 1);
  EXPECT_EQ(only_cancelled.orders(0).id(), ids[1]);

  grpc::ClientContext bad;
  pb::ListOrdersRequest request;
  request.set_page_token("garbage");
  pb::ListOrdersResponse response;
  EXPECT_EQ(orders_->ListOrders(WithDeadline(bad), request, &response).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
}

TEST_F(OrderFlowTest, RestartOnTheSameDatabaseKeepsEveryAcknowledgedOrder) {
  StartServer();
  std::vector<pb::Order> acknowledged;
  std::string assigned_id;
  {
    OrderWatcher watcher(channel_);
    for (int i = 0; i < 4; ++i) {
      pb::SubmitOrderResponse r;
      ASSERT_TRUE(Submit(OrderRequest("keep-" + std::to_string(i), {"K3-2-3N"}, "D-B2"), &r).ok());
      acknowledged.push_back(r.order());
    }
    FakeRobot robot(channel_, "R1");
    robot.Connect(kP1x, kP1y);
    auto assigned = watcher.WaitForState(acknowledged[0].id(), pb::ORDER_STATE_ASSIGNED);
    ASSERT_TRUE(assigned);
    assigned_id = assigned->order_id();
  }
  StopServer();
  StartServer();

  auto listed = List();
  ASSERT_EQ(listed.orders_size(), 4);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(listed.orders(i).id(), acknowledged[static_cast<std::size_t>(i)].id());
    EXPECT_EQ(listed.orders(i).client_order_id(), acknowledged[static_cast<std::size_t>(i)].client_order_id());
  }
  const pb::Order kept = Get(assigned_id);
  EXPECT_NE(kept.state(), pb::ORDER_STATE_ACCEPTED);
  EXPECT_EQ(kept.robot_ids(0), "R1");
  grpc::ClientContext ctx;
  pb::ExplainAllocationRequest explain;
  explain.set_order_id(assigned_id);
  pb::AllocationExplanation explanation;
  ASSERT_TRUE(orders_->ExplainAllocation(WithDeadline(ctx), explain, &explanation).ok());
  EXPECT_EQ(explanation.winner_ids(0), "R1");

  // A repeat is recognised; a new order gets a new id.
  pb::SubmitOrderResponse repeat, fresh;
  ASSERT_TRUE(Submit(OrderRequest("keep-2", {"K3-2-3N"}, "D-B2"), &repeat).ok());
  EXPECT_FALSE(repeat.created());
  EXPECT_EQ(repeat.order().id(), acknowledged[2].id());
  ASSERT_TRUE(Submit(OrderRequest("keep-new", {"K3-2-3N"}, "D-B2"), &fresh).ok());
  EXPECT_TRUE(fresh.created());
  for (const auto& o : acknowledged) EXPECT_NE(o.id(), fresh.order().id());

  // The robot's plan is resent when it reconnects.
  FakeRobot robot(channel_, "R1");
  robot.Connect(kP1x, kP1y);
  auto resent = robot.WaitFor(pb::ServerMessage::kAssignment);
  ASSERT_TRUE(resent);
  EXPECT_EQ(resent->assignment().order_ids(0), assigned_id);
}

TEST_F(OrderFlowTest, StoreWriteFailureIsAnErrorAndNothingIsHalfStored) {
  auto sqlite = storage::SqliteStore::Open(config_.db);
  ASSERT_TRUE(sqlite.ok()) << sqlite.error().message;
  storage::FaultInjectionStore faulty(**sqlite);
  StartServer(&faulty);

  faulty.FailWritesFrom(faulty.writes() + 1);
  pb::SubmitOrderResponse response;
  const grpc::Status status = Submit(OrderRequest("fragile", {"K3-2-3N"}, "D-B2"), &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAVAILABLE);
  EXPECT_NE(status.error_message().find("NOT accepted"), std::string::npos) << status.error_message();
  EXPECT_EQ(List().orders_size(), 0);
  auto stored = (*sqlite)->GetOrderByClientId("fragile");
  EXPECT_FALSE(stored.ok());
  auto events = (*sqlite)->ListEvents({});
  ASSERT_TRUE(events.ok());
  EXPECT_TRUE(events->empty());

  // Once the disk works again the same submission is accepted as new.
  faulty.FailWritesFrom(0);
  ASSERT_TRUE(Submit(OrderRequest("fragile", {"K3-2-3N"}, "D-B2"), &response).ok());
  EXPECT_TRUE(response.created());
  EXPECT_TRUE((*sqlite)->GetOrderByClientId("fragile").ok());
  StopServer();
}

TEST_F(OrderFlowTest, AFailedAwardLeavesTheOrderAcceptedAndIsRetried) {
  auto sqlite = storage::SqliteStore::Open(config_.db);
  ASSERT_TRUE(sqlite.ok()) << sqlite.error().message;
  storage::FaultInjectionStore faulty(**sqlite);
  StartServer(&faulty);
  OrderWatcher watcher(channel_);
  pb::SubmitOrderResponse submitted;
  ASSERT_TRUE(Submit(OrderRequest("retry", {"K3-2-3N"}, "D-B2"), &submitted).ok());
  // The robot registers (one write), then the award's writes fail once.
  FakeRobot robot(channel_, "R1");
  faulty.FailWrite(faulty.writes() + 2);
  robot.Connect(kP1x, kP1y);
  auto assigned = watcher.WaitForState(submitted.order().id(), pb::ORDER_STATE_ASSIGNED);
  ASSERT_TRUE(assigned);
  EXPECT_GE(faulty.failures(), 1u);
  auto stored = (*sqlite)->GetOrder(submitted.order().id());
  ASSERT_TRUE(stored.ok());
  EXPECT_EQ(stored->order.state, engine::OrderState::kAssigned);
  robot.Disconnect();
  StopServer();
}

TEST_F(OrderFlowTest, HeartbeatLossReallocatesAfterTheGrace) {
  config_.heartbeat_interval = 0.05;
  config_.heartbeat_timeout = 0.5;
  config_.offline_grace = 0.2;
  StartServer();
  OrderWatcher watcher(channel_);
  FakeRobot silent(channel_, "R1");
  silent.Connect(kP1x, kP1y);
  ASSERT_TRUE(silent.WaitFor(pb::ServerMessage::kWelcome));
  pb::SubmitOrderResponse submitted;
  ASSERT_TRUE(Submit(OrderRequest("orphan", {"K1-1-1N"}, "D-B1"), &submitted).ok());
  const std::string id = submitted.order().id();
  auto first = watcher.WaitForState(id, pb::ORDER_STATE_ASSIGNED);
  ASSERT_TRUE(first);
  EXPECT_EQ(first->robot_ids(0), "R1");
  // R1 says nothing more: the server ends its stream and, after the grace, re-allocates.
  const grpc::Status ended = silent.AwaitEnd();
  EXPECT_EQ(ended.error_code(), grpc::StatusCode::UNAVAILABLE);
  EXPECT_NE(ended.error_message().find("heartbeat"), std::string::npos) << ended.error_message();
  ASSERT_TRUE(watcher.WaitForState(id, pb::ORDER_STATE_ACCEPTED));
  FakeRobot spare(channel_, "R2");
  spare.Connect(kP2x, kP2y);
  auto second = watcher.WaitForState(id, pb::ORDER_STATE_ASSIGNED);
  ASSERT_TRUE(second);
  EXPECT_EQ(second->robot_ids(0), "R2");
  spare.Disconnect();
}

TEST_F(OrderFlowTest, GetMapAnswersTheFloor) {
  StartServer();
  auto stub = pb::MapService::NewStub(channel_);
  grpc::ClientContext ctx;
  pb::GetMapResponse map;
  ASSERT_TRUE(stub->GetMap(WithDeadline(ctx), pb::GetMapRequest(), &map).ok());
  EXPECT_EQ(map.map().name(), "chu2024");
  EXPECT_EQ(map.map().points_size(), 526);
  EXPECT_FALSE(map.version().empty());
  auto stored = server_->dispatcher().store().LatestMapVersion();
  ASSERT_TRUE(stored.ok());
  EXPECT_EQ(stored->content_hash, map.version());
}

}  // namespace
}  // namespace dispatch::server::testing
