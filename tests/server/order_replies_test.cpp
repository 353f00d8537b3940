// What the order commands answer before the dispatch core has a say (server/order_replies.h):
// a repeated client order id, an order the store did not insert, a cancel of an order that is
// unknown or finished; and the view of a stored order (server/order_views.h, StoredView).
#include "server/order_replies.h"

#include <gtest/gtest.h>

#include "server/order_views.h"
#include "storage/store.h"

namespace dispatch::server {
namespace {

engine::Order Order(const std::string& client_id) {
  engine::Order o;
  o.id = "ord-000001";
  o.client_id = client_id;
  o.picks = {1};
  o.drop = 2;
  return o;
}

std::shared_ptr<const OrderView> ViewOf(const engine::Order& order, engine::OrderState state) {
  storage::OrderRecord record;
  record.order = order;
  record.order.state = state;
  record.content_hash = storage::OrderContentHash(order);
  record.updated_time = 8.0;
  return StoredView(record);
}

TEST(OrderRepliesTest, ARepeatedClientOrderIdIsTheSameOrderOnlyWithTheSameContent) {
  const engine::Order order = Order("wms-1");
  auto existing = ViewOf(order, engine::OrderState::kAssigned);
  const SubmitReply repeat = AnswerRepeat(existing, order);
  EXPECT_TRUE(repeat.status.ok());
  EXPECT_EQ(repeat.order, existing);
  EXPECT_FALSE(repeat.created);
  engine::Order other = order;
  other.drop = 3;
  const SubmitReply clash = AnswerRepeat(existing, other);
  EXPECT_EQ(clash.status.code, StatusCode::kAlreadyExists);
  EXPECT_EQ(clash.order, nullptr);
  EXPECT_NE(clash.status.message.find("'wms-1' already names order ord-000001"), std::string::npos);
}

TEST(OrderRepliesTest, AnOrderTheStoreDidNotInsertSaysWhy) {
  const ServiceStatus taken = NotInserted({engine::ErrorCode::kFailedPrecondition, "other content"}, "wms-1");
  EXPECT_EQ(taken.code, StatusCode::kAlreadyExists);
  EXPECT_EQ(taken.message, "other content");
  const ServiceStatus failed = NotInserted({engine::ErrorCode::kIoError, "disk full"}, "wms-1");
  EXPECT_EQ(failed.code, StatusCode::kUnavailable);
  EXPECT_EQ(failed.message.rfind("order 'wms-1' was NOT accepted: ", 0), 0u);
  EXPECT_NE(failed.message.find("disk full"), std::string::npos);
}

TEST(OrderRepliesTest, OnlyAnOpenOrderGoesToTheCoreToBeCancelled) {
  const engine::Order order = Order("wms-1");
  const auto unknown = AnswerCancelOfClosed(nullptr, "ord-000009");
  ASSERT_TRUE(unknown.has_value());
  EXPECT_EQ(unknown->status.code, StatusCode::kNotFound);
  EXPECT_EQ(unknown->status.message, "no order with id 'ord-000009'");
  auto cancelled = ViewOf(order, engine::OrderState::kCancelled);
  const auto again = AnswerCancelOfClosed(cancelled, order.id);
  ASSERT_TRUE(again.has_value());
  EXPECT_TRUE(again->status.ok());  // cancelling twice is fine
  EXPECT_EQ(again->order, cancelled);
  const auto completed = AnswerCancelOfClosed(ViewOf(order, engine::OrderState::kCompleted), order.id);
  ASSERT_TRUE(completed.has_value());
  EXPECT_EQ(completed->status.code, StatusCode::kFailedPrecondition);
  EXPECT_EQ(completed->status.message, "order ord-000001 is already completed; only open orders can be cancelled");
  for (auto open : {engine::OrderState::kAccepted, engine::OrderState::kAssigned, engine::OrderState::kInProgress}) {
    EXPECT_FALSE(AnswerCancelOfClosed(ViewOf(order, open), order.id).has_value());
  }
}

TEST(OrderRepliesTest, AStoredViewIsFinishedAtItsLastUpdateWhenTerminal) {
  const engine::Order order = Order("wms-1");
  EXPECT_FALSE(ViewOf(order, engine::OrderState::kAssigned)->finished_time.has_value());
  EXPECT_EQ(ViewOf(order, engine::OrderState::kFailed)->finished_time.value_or(-1.0), 8.0);
}

}  // namespace
}  // namespace dispatch::server
