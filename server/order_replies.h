// SubmitReply, OrderReply: what the dispatcher's order commands answer (Dispatcher::SubmitOrder,
// CancelOrder), and the answers they give from the order views and the store alone, before
// the dispatch core has a say: a client order id that is taken already, an order the store
// did not insert, a cancel of an order that is unknown or finished. Plain values and
// functions.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "engine/common/result.h"
#include "engine/fleet/order.h"
#include "server/service_status.h"
#include "server/snapshot.h"

namespace dispatch::server {

struct SubmitReply {
  ServiceStatus status;
  std::shared_ptr<const OrderView> order;
  bool created = false;
};

struct OrderReply {
  ServiceStatus status;
  std::shared_ptr<const OrderView> order;
};

// `order` is submitted with a client order id that already names `existing`: with the same
// content (storage::OrderContentHash) it is a repeat, answered with `existing` (not created);
// with other content ALREADY_EXISTS.
SubmitReply AnswerRepeat(std::shared_ptr<const OrderView> existing, const engine::Order& order);

// The store did not insert the order with client order id `client_id`: ALREADY_EXISTS when it
// holds that id with other content (kFailedPrecondition), else the error's status; a storage
// failure (UNAVAILABLE) says that the order was NOT accepted.
ServiceStatus NotInserted(const engine::Error& error, const std::string& client_id);

// A cancel of `view` (null: no order with id `order_id`) answered without the core: NOT_FOUND,
// the order itself when it is cancelled already, FAILED_PRECONDITION when it finished
// otherwise; nullopt for an open order (the core plans its cancel).
std::optional<OrderReply> AnswerCancelOfClosed(std::shared_ptr<const OrderView> view, const std::string& order_id);

}  // namespace dispatch::server
