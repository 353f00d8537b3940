#include "server/fleet_service.h"

#include "server/grpc_status.h"
#include "server/proto_convert.h"
#include "server/queued_writer.h"

namespace dispatch::server {
namespace {

class RobotStreamReactor;

// The dispatcher's handle on a robot stream; outlives it (the stream detaches in OnDone).
class StreamLink final : public RobotLink {
 public:
  explicit StreamLink(RobotStreamReactor* session) : session_(session) {}
  void Send(RobotOutbound message) override;
  void Close(ServiceStatus status) override;
  void Detach() {
    std::lock_guard<std::mutex> lock(mu_);
    session_ = nullptr;
  }

 private:
  std::mutex mu_;  // guards session_ (deleted only after Detach)
  RobotStreamReactor* session_;
};

class RobotStreamReactor final
    : public QueuedWriter<grpc::ServerBidiReactor<pb::RobotMessage, pb::ServerMessage>, pb::ServerMessage> {
 public:
  explicit RobotStreamReactor(Dispatcher& dispatcher)
      : dispatcher_(dispatcher), link_(std::make_shared<StreamLink>(this)) {
    StartRead(&in_);
  }

  void OnReadDone(bool ok) override {
    if (!ok) {  // the robot closed its side or the call broke
      dispatcher_.OnRobotGone(link_);
      RequestFinish(grpc::Status::OK);
      return;
    }
    auto message = RobotInboundFromProto(in_);
    if (!message.ok()) {
      dispatcher_.OnRobotGone(link_);
      RequestFinish(Fitted(ToGrpcStatus(FromEngineError(message.error()))));
      return;
    }
    dispatcher_.OnRobotMessage(link_, std::move(message).value());
    StartRead(&in_);
  }

  void OnDone() override {
    link_->Detach();
    dispatcher_.OnRobotGone(link_);
    delete this;
  }

 private:
  Dispatcher& dispatcher_;
  std::shared_ptr<StreamLink> link_;
  pb::RobotMessage in_;
};

void StreamLink::Send(RobotOutbound message) {
  pb::ServerMessage out;
  OutboundToProto(message, &out);
  std::lock_guard<std::mutex> lock(mu_);
  if (session_) session_->Enqueue(std::move(out));
}

void StreamLink::Close(ServiceStatus status) {
  std::lock_guard<std::mutex> lock(mu_);
  if (session_) session_->RequestFinish(Fitted(ToGrpcStatus(status)));
}

}  // namespace

grpc::ServerBidiReactor<pb::RobotMessage, pb::ServerMessage>* FleetServiceImpl::Connect(
    grpc::CallbackServerContext* /*context*/) {
  return new RobotStreamReactor(dispatcher_);
}

MapServiceImpl::MapServiceImpl(const Dispatcher& dispatcher) {
  MapToProto(dispatcher.map(), dispatcher.options().map_version, &map_);
}

grpc::ServerUnaryReactor* MapServiceImpl::GetMap(grpc::CallbackServerContext* context,
                                                 const pb::GetMapRequest* /*request*/,
                                                 pb::GetMapResponse* response) {
  *response = map_;
  auto* reactor = context->DefaultReactor();
  reactor->Finish(grpc::Status::OK);
  return reactor;
}

}  // namespace dispatch::server
