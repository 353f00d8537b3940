#include "server/order_replies.h"

#include <utility>

#include "storage/store.h"

namespace dispatch::server {

SubmitReply AnswerRepeat(std::shared_ptr<const OrderView> existing, const engine::Order& order) {
  SubmitReply reply;
  if (storage::OrderContentHash(order) == existing->record.content_hash) {
    reply.order = std::move(existing);
    reply.created = false;
    return reply;
  }
  reply.status = MakeStatus(
      StatusCode::kAlreadyExists,
      "client_order_id '" + order.client_id + "' already names order " + existing->record.order.id +
          " with different content; this submission (picks, drop, formation, priority, work time or release "
          "time) differs from it");
  return reply;
}

ServiceStatus NotInserted(const engine::Error& error, const std::string& client_id) {
  ServiceStatus status = error.code == engine::ErrorCode::kFailedPrecondition
                             ? MakeStatus(StatusCode::kAlreadyExists, error.message)
                             : FromEngineError(error);
  if (status.code == StatusCode::kUnavailable) {
    status.message = "order '" + client_id + "' was NOT accepted: " + status.message;
  }
  return status;
}

std::optional<OrderReply> AnswerCancelOfClosed(std::shared_ptr<const OrderView> view, const std::string& order_id) {
  OrderReply reply;
  if (!view) {
    reply.status = MakeStatus(StatusCode::kNotFound, "no order with id '" + order_id + "'");
    return reply;
  }
  const engine::OrderState state = view->record.order.state;
  if (state == engine::OrderState::kCancelled) {
    reply.order = std::move(view);
    return reply;
  }
  if (engine::IsTerminal(state)) {
    reply.status = MakeStatus(StatusCode::kFailedPrecondition,
                              "order " + order_id + " is already " + engine::OrderStateName(state) +
                                  "; only open orders can be cancelled");
    return reply;
  }
  return std::nullopt;
}

}  // namespace dispatch::server
