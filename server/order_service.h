// OrderService (proto/warehouse/dispatch/v1/orders.proto) on gRPC's callback API. Writes go
// to the dispatcher loop and finish from its reply callback (no thread waits); reads use the
// published snapshot; WatchOrders replays the journal from the store and then streams live
// events from the dispatcher's WatchHub. Thread-safe.
#pragma once

#include "server/auth.h"
#include "server/dispatcher.h"
#include "warehouse/dispatch/v1/orders.grpc.pb.h"

namespace dispatch::server {

// SubmitOrder takes its request as bytes and parses it itself: gRPC's callback API answers a
// request that does not parse with UNIMPLEMENTED and no message (grpcpp's
// server_callback_handlers.h); a malformed order gets INVALID_ARGUMENT saying what it is.
class OrderServiceImpl final : public ::warehouse::dispatch::v1::OrderService::WithRawCallbackMethod_SubmitOrder<
                                   ::warehouse::dispatch::v1::OrderService::CallbackService> {
 public:
  // Every call is authorized first (server/auth.h: submit, read, cancel orders).
  OrderServiceImpl(Dispatcher& dispatcher, const Authenticator& auth) : dispatcher_(dispatcher), auth_(auth) {}

  grpc::ServerUnaryReactor* SubmitOrder(grpc::CallbackServerContext* context, const grpc::ByteBuffer* request,
                                        grpc::ByteBuffer* response) override;
  grpc::ServerUnaryReactor* GetOrder(grpc::CallbackServerContext* context,
                                     const ::warehouse::dispatch::v1::GetOrderRequest* request,
                                     ::warehouse::dispatch::v1::Order* response) override;
  grpc::ServerUnaryReactor* CancelOrder(grpc::CallbackServerContext* context,
                                        const ::warehouse::dispatch::v1::CancelOrderRequest* request,
                                        ::warehouse::dispatch::v1::Order* response) override;
  grpc::ServerUnaryReactor* ListOrders(grpc::CallbackServerContext* context,
                                       const ::warehouse::dispatch::v1::ListOrdersRequest* request,
                                       ::warehouse::dispatch::v1::ListOrdersResponse* response) override;
  grpc::ServerWriteReactor<::warehouse::dispatch::v1::OrderEvent>* WatchOrders(
      grpc::CallbackServerContext* context,
      const ::warehouse::dispatch::v1::WatchOrdersRequest* request) override;
  grpc::ServerUnaryReactor* ExplainAllocation(
      grpc::CallbackServerContext* context,
      const ::warehouse::dispatch::v1::ExplainAllocationRequest* request,
      ::warehouse::dispatch::v1::AllocationExplanation* response) override;

 private:
  Dispatcher& dispatcher_;
  const Authenticator& auth_;
};

}  // namespace dispatch::server
