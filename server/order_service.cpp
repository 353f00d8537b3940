#include "server/order_service.h"

#include <optional>
#include <set>

#include "server/grpc_auth.h"
#include "server/grpc_status.h"
#include "server/proto_convert.h"
#include "server/queued_writer.h"

namespace dispatch::server {
namespace {

grpc::ServerUnaryReactor* Done(grpc::CallbackServerContext* context, grpc::Status status) {
  auto* reactor = context->DefaultReactor();
  reactor->Finish(Fitted(std::move(status)));
  return reactor;
}

// nullopt when the call may go on, else its refusal.
std::optional<grpc::Status> Refused(const Authenticator& auth, const grpc::CallbackServerContext& context,
                                    Access access) {
  const Authenticator::Outcome outcome = AuthorizeCall(auth, context, access);
  if (outcome.status.ok()) return std::nullopt;
  return ToGrpcStatus(outcome.status);
}

// One WatchOrders stream: subscribed to the hub before the replay so nothing falls between.
class WatchReactor final : public QueuedWriter<grpc::ServerWriteReactor<pb::OrderEvent>, pb::OrderEvent> {
 public:
  WatchReactor(Dispatcher& dispatcher, const pb::WatchOrdersRequest& request)
      : dispatcher_(dispatcher), filter_(request.order_ids().begin(), request.order_ids().end()) {
    sink_ = std::make_shared<Sink>(this);
    sub_ = dispatcher_.watch_hub().Subscribe(sink_);
    if (request.from_start()) {
      Replay(0);
    } else if (request.after_event_id() > 0) {
      Replay(static_cast<std::int64_t>(request.after_event_id()));
    }
    std::vector<storage::OrderEvent> live;
    {
      std::lock_guard<std::mutex> lock(mu_);
      replaying_ = false;
      live.swap(buffered_);
    }
    for (const auto& e : live) Deliver(e);
  }

  void OnDone() override {
    dispatcher_.watch_hub().Unsubscribe(sub_);
    sink_->Detach();
    delete this;
  }
  void OnCancel() override { RequestFinish(grpc::Status::CANCELLED); }

 private:
  class Sink final : public OrderEventSink {
   public:
    explicit Sink(WatchReactor* owner) : owner_(owner) {}
    void OnEvent(const storage::OrderEvent& event) override {
      std::lock_guard<std::mutex> lock(mu_);
      if (owner_) owner_->OnLive(event);
    }
    void OnClose() override {
      std::lock_guard<std::mutex> lock(mu_);
      if (owner_) owner_->RequestFinish({grpc::StatusCode::UNAVAILABLE, "server shutting down"});
    }
    void Detach() {
      std::lock_guard<std::mutex> lock(mu_);
      owner_ = nullptr;
    }

   private:
    std::mutex mu_;  // guards owner_ (the reactor is deleted only after Detach)
    WatchReactor* owner_;
  };

  void Replay(std::int64_t after) {
    storage::EventQuery query;
    query.after_id = after;
    if (filter_.size() == 1) query.order_id = *filter_.begin();
    query.limit = 1000;
    for (;;) {
      auto events = dispatcher_.store().ListEvents(query);
      if (!events.ok()) {
        RequestFinish({grpc::StatusCode::UNAVAILABLE, "journal replay failed: " + events.error().message});
        return;
      }
      for (const auto& e : *events) {
        Deliver(e);
        query.after_id = e.id;
      }
      if (events->size() < static_cast<std::size_t>(query.limit)) break;
    }
  }

  void OnLive(const storage::OrderEvent& event) {
    {
      std::lock_guard<std::mutex> lock(mu_);
      if (replaying_) {
        buffered_.push_back(event);
        return;
      }
    }
    Deliver(event);
  }

  void Deliver(const storage::OrderEvent& event) {
    {
      std::lock_guard<std::mutex> lock(mu_);
      if (event.id <= last_sent_) return;  // replayed already
      last_sent_ = event.id;
    }
    if (!filter_.empty() && !filter_.count(event.order_id)) return;
    pb::OrderEvent out;
    EventToProto(event, &out);
    Enqueue(std::move(out));
  }

  Dispatcher& dispatcher_;
  const std::set<std::string> filter_;
  std::shared_ptr<Sink> sink_;
  std::uint64_t sub_ = 0;
  std::mutex mu_;  // guards replaying_, buffered_, last_sent_
  bool replaying_ = true;
  std::vector<storage::OrderEvent> buffered_;
  std::int64_t last_sent_ = 0;
};

constexpr int kDefaultPageSize = 100;

}  // namespace

grpc::ServerUnaryReactor* OrderServiceImpl::SubmitOrder(grpc::CallbackServerContext* context,
                                                        const grpc::ByteBuffer* request,
                                                        grpc::ByteBuffer* response) {
  const Authenticator::Outcome auth = AuthorizeCall(auth_, *context, Access::kSubmitOrder);
  if (!auth.status.ok()) return Done(context, ToGrpcStatus(auth.status));
  pb::SubmitOrderRequest parsed;
  grpc::ByteBuffer bytes(*request);  // Deserialize consumes its buffer
  if (!grpc::SerializationTraits<pb::SubmitOrderRequest>::Deserialize(&bytes, &parsed).ok()) {
    return Done(context, {grpc::StatusCode::INVALID_ARGUMENT,
                          "the request does not parse as a warehouse.dispatch.v1.SubmitOrderRequest "
                          "(malformed protobuf, or a string field that is not UTF-8)"});
  }
  auto converted = OrderRequestFromProto(parsed);
  if (!converted.ok()) return Done(context, ToGrpcStatus(FromEngineError(converted.error())));
  auto* reactor = context->DefaultReactor();
  dispatcher_.SubmitOrder(std::move(converted).value(), auth.principal.name,
                          [this, reactor, response](SubmitReply reply) {
    if (reply.status.ok()) {
      pb::SubmitOrderResponse out;
      OrderToProto(*reply.order, dispatcher_.map(), out.mutable_order());
      out.set_created(reply.created);
      bool own_buffer = false;
      if (!grpc::SerializationTraits<pb::SubmitOrderResponse>::Serialize(out, response, &own_buffer).ok()) {
        reactor->Finish({grpc::StatusCode::INTERNAL, "the stored order could not be serialized"});
        return;
      }
    }
    reactor->Finish(Fitted(ToGrpcStatus(reply.status)));
  });
  return reactor;
}

grpc::ServerUnaryReactor* OrderServiceImpl::GetOrder(grpc::CallbackServerContext* context,
                                                     const pb::GetOrderRequest* request,
                                                     pb::Order* response) {
  if (auto refused = Refused(auth_, *context, Access::kReadOrders)) return Done(context, std::move(*refused));
  engine::Result<std::shared_ptr<const OrderView>> order = std::shared_ptr<const OrderView>();
  std::string key;
  switch (request->key_case()) {
    case pb::GetOrderRequest::kOrderId:
      order = dispatcher_.FindAnywhere(request->order_id(), false, false);
      key = "id '" + request->order_id() + "'";
      break;
    case pb::GetOrderRequest::kClientOrderId:
      order = dispatcher_.FindAnywhere(request->client_order_id(), true, false);
      key = "client_order_id '" + request->client_order_id() + "'";
      break;
    case pb::GetOrderRequest::KEY_NOT_SET:
      return Done(context, {grpc::StatusCode::INVALID_ARGUMENT, "give order_id or client_order_id"});
  }
  if (!order.ok()) return Done(context, ToGrpcStatus(FromEngineError(order.error())));
  if (!*order) return Done(context, {grpc::StatusCode::NOT_FOUND, "no order with " + key});
  OrderToProto(**order, dispatcher_.map(), response);
  return Done(context, grpc::Status::OK);
}

grpc::ServerUnaryReactor* OrderServiceImpl::CancelOrder(grpc::CallbackServerContext* context,
                                                        const pb::CancelOrderRequest* request,
                                                        pb::Order* response) {
  const Authenticator::Outcome auth = AuthorizeCall(auth_, *context, Access::kCancelOrder);
  if (!auth.status.ok()) return Done(context, ToGrpcStatus(auth.status));
  if (request->order_id().empty()) {
    return Done(context, {grpc::StatusCode::INVALID_ARGUMENT, "order_id is required"});
  }
  auto* reactor = context->DefaultReactor();
  dispatcher_.CancelOrder(request->order_id(), request->reason(), auth.principal.name,
                          [this, reactor, response](OrderReply reply) {
                            if (reply.status.ok()) OrderToProto(*reply.order, dispatcher_.map(), response);
                            reactor->Finish(Fitted(ToGrpcStatus(reply.status)));
                          });
  return reactor;
}

grpc::ServerUnaryReactor* OrderServiceImpl::ListOrders(grpc::CallbackServerContext* context,
                                                       const pb::ListOrdersRequest* request,
                                                       pb::ListOrdersResponse* response) {
  if (auto refused = Refused(auth_, *context, Access::kReadOrders)) return Done(context, std::move(*refused));
  // From the store: it holds every order (memory only the open ones and the newest
  // finished), and it is written before the snapshot changes, so it is never behind it.
  storage::OrderQuery query;
  std::set<engine::OrderState> states;
  for (int s : request->states()) {
    if (s == pb::ORDER_STATE_UNSPECIFIED) continue;  // "no filter" (common.proto)
    auto state = OrderStateFromProto(static_cast<pb::OrderState>(s));
    if (!state) {
      return Done(context, {grpc::StatusCode::INVALID_ARGUMENT,
                            "states: " + std::to_string(s) + " is not an OrderState"});
    }
    if (states.insert(*state).second) query.states.push_back(*state);
  }
  if (request->page_size() < 0) {
    return Done(context, {grpc::StatusCode::INVALID_ARGUMENT, "page_size must be >= 0"});
  }
  query.page_size = request->page_size() == 0 ? kDefaultPageSize
                                              : std::min(request->page_size(), storage::kMaxPageSize);
  query.page_token = request->page_token();
  auto page = dispatcher_.store().ListOrders(query);
  if (!page.ok()) {
    if (page.error().code == engine::ErrorCode::kInvalidArgument) {
      return Done(context, {grpc::StatusCode::INVALID_ARGUMENT,
                            "page_token '" + request->page_token() + "' is not one this server issued"});
    }
    return Done(context, ToGrpcStatus(FromEngineError(page.error())));
  }
  OrderView view;
  for (auto& record : page->orders) {
    view.record = std::move(record);
    view.finished_time.reset();
    if (engine::IsTerminal(view.record.order.state)) view.finished_time = view.record.updated_time;
    OrderToProto(view, dispatcher_.map(), response->add_orders());
  }
  response->set_next_page_token(page->next_page_token);
  return Done(context, grpc::Status::OK);
}

// A WatchOrders call refused before it starts (it names an order that does not exist).
class RefusedWatch final : public grpc::ServerWriteReactor<pb::OrderEvent> {
 public:
  explicit RefusedWatch(grpc::Status status) { Finish(std::move(status)); }
  void OnDone() override { delete this; }
};

grpc::ServerWriteReactor<pb::OrderEvent>* OrderServiceImpl::WatchOrders(
    grpc::CallbackServerContext* context, const pb::WatchOrdersRequest* request) {
  if (auto refused = Refused(auth_, *context, Access::kReadOrders)) return new RefusedWatch(Fitted(std::move(*refused)));
  // Named orders must exist (a submitted order is in the snapshot before SubmitOrder replies).
  for (const std::string& id : request->order_ids()) {
    auto order = dispatcher_.FindAnywhere(id, false, false);
    if (!order.ok()) return new RefusedWatch(Fitted(ToGrpcStatus(FromEngineError(order.error()))));
    if (!*order) return new RefusedWatch(Fitted({grpc::StatusCode::NOT_FOUND, "no order with id '" + id + "'"}));
  }
  return new WatchReactor(dispatcher_, *request);
}

grpc::ServerUnaryReactor* OrderServiceImpl::ExplainAllocation(
    grpc::CallbackServerContext* context, const pb::ExplainAllocationRequest* request,
    pb::AllocationExplanation* response) {
  if (auto refused = Refused(auth_, *context, Access::kReadOrders)) return Done(context, std::move(*refused));
  auto found = dispatcher_.FindAnywhere(request->order_id(), false, true);
  if (!found.ok()) return Done(context, ToGrpcStatus(FromEngineError(found.error())));
  const std::shared_ptr<const OrderView> order = *found;
  if (!order) {
    return Done(context, {grpc::StatusCode::NOT_FOUND, "no order with id '" + request->order_id() + "'"});
  }
  if (!order->explanation) {
    return Done(context, {grpc::StatusCode::FAILED_PRECONDITION,
                          "order " + request->order_id() + " has not been allocated yet (state " +
                              engine::OrderStateName(order->record.order.state) + ")"});
  }
  AllocationToProto(*order->explanation, dispatcher_.map(), response);
  return Done(context, grpc::Status::OK);
}

}  // namespace dispatch::server
