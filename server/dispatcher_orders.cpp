// Dispatcher: the order commands (submit, cancel) and finding an order anywhere (the book,
// server/order_views.h, else the store).
#include <spdlog/spdlog.h>

#include <algorithm>

#include "engine/dispatch/order_intake.h"
#include "server/dispatcher.h"

namespace dispatch::server {

engine::Result<std::shared_ptr<const OrderView>> Dispatcher::FindAnywhere(const std::string& key, bool by_client_id,
                                                                          bool explain) const {
  auto snap = snapshot();
  if (auto view = by_client_id ? snap->FindClientOrder(key) : snap->FindOrder(key)) return view;
  return OrderViews::FromStore(store_, key, by_client_id, explain);
}

std::string Dispatcher::NextOrderId() {
  char buf[32];
  std::snprintf(buf, sizeof buf, "ord-%06lld", static_cast<long long>(last_order_number_ + 1));
  return buf;
}

// --- Orders --------------------------------------------------------------------------------

void Dispatcher::SubmitOrder(engine::OrderRequest request, std::string actor, std::function<void(SubmitReply)> done) {
  // The route searches towards the order's stops run first, on the route worker: the loop's
  // reachability check and the auction then find them cached.
  auto shared = std::make_shared<const engine::OrderRequest>(std::move(request));
  route_worker_->Run([this, shared, actor = std::move(actor), done = std::move(done)](bool cancelled) {
    if (!cancelled) {
      for (const engine::PointId p : engine::StopsOf(*map_, *shared, options_.snap)) routes_->Prepare(p);
    }
    Post([this, shared, actor, done] {
      DoSubmit(*shared, actor, [this, done](SubmitReply reply) {
        Defer([done, reply = std::move(reply)]() mutable { done(std::move(reply)); });
      });
    });
  });
}

void Dispatcher::CancelOrder(std::string order_id, std::string reason, std::string actor,
                             std::function<void(OrderReply)> done) {
  Post([this, order_id = std::move(order_id), reason = std::move(reason), actor = std::move(actor),
        done = std::move(done)] {
    DoCancel(order_id, reason, actor, [this, done](OrderReply reply) {
      Defer([done, reply = std::move(reply)]() mutable { done(std::move(reply)); });
    });
  });
}

void Dispatcher::DoSubmit(const engine::OrderRequest& request, const std::string& actor,
                          const std::function<void(SubmitReply)>& done) {
  SubmitReply reply;
  engine::OrderRequest req = request;
  req.created_time = Now();
  auto admitted = engine::AdmitOrder(*map_, *routes_, req, options_.snap, NextOrderId());
  if (!admitted.ok()) {
    reply.status = FromEngineError(admitted.error());
    return done(std::move(reply));
  }
  engine::Order order = std::move(admitted).value();
  if (auto existing = book_.FindClient(order.client_id)) return done(AnswerRepeat(std::move(existing), order));
  // Not in memory: new, or finished long ago (retired). The store decides which.
  auto inserted = store_.InsertOrder(order, actor);
  if (!inserted.ok()) {
    reply.status = NotInserted(inserted.error(), order.client_id);
    spdlog::warn("submit {}: {}", order.client_id, reply.status.message);
    return done(std::move(reply));
  }
  auto view = StoredView(inserted->record);
  reply.order = view;
  reply.created = inserted->created;
  // A repeat of a retired order is answered from the store; a new one joins the book and the core.
  if (!inserted->created) return done(std::move(reply));
  ++last_order_number_;
  book_.Put(view);
  effects_.MarkChanged();
  core_->AddOrder(std::move(order));
  done(std::move(reply));
  storage::EventQuery first;
  first.order_id = view->record.order.id;
  first.limit = 1;
  if (auto events = store_.ListEvents(first); events.ok() && !events->empty()) {
    Journal(events->front());
  }
  spdlog::info("order {} ({}) accepted{}", view->record.order.id, view->record.order.client_id,
               actor.empty() ? "" : " from " + actor);
}

void Dispatcher::DoCancel(const std::string& order_id, const std::string& reason, const std::string& actor,
                          const std::function<void(OrderReply)>& done) {
  OrderReply reply;
  if (reason.size() > kMaxCancelReasonBytes) {  // stored and sent back with the order: bounded
    reply.status = MakeStatus(StatusCode::kInvalidArgument, "the cancel reason is longer than " +
                                                                std::to_string(kMaxCancelReasonBytes) + " bytes (" +
                                                                std::to_string(reason.size()) + ")");
    return done(std::move(reply));
  }
  auto view = book_.Find(order_id);
  if (!view) {  // retired (finished) or unknown
    auto stored = FindAnywhere(order_id, false, false);
    if (!stored.ok()) {
      reply.status = FromEngineError(stored.error());
      return done(std::move(reply));
    }
    view = *stored;
  }
  if (auto answer = AnswerCancelOfClosed(view, order_id)) return done(std::move(*answer));
  const std::string why = reason.empty() ? "cancelled by client" : reason;
  auto change = core_->PlanCancel(order_id, why, Now());
  if (!change.ok()) {  // open in the views, not in the core: cannot happen
    reply.status = FromEngineError(change.error());
    return done(std::move(reply));
  }
  if (!Commit(*change, nullptr, &reply.status, actor)) return done(std::move(reply));
  reply.order = book_.Find(order_id);
  done(std::move(reply));
}

}  // namespace dispatch::server
