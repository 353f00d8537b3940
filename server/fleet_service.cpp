#include "server/fleet_service.h"

#include <algorithm>

#include "engine/common/text.h"
#include "server/grpc_auth.h"
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
  // `allowed`: the robot ids its Hello may name (empty: any); `who` says whose they are.
  RobotStreamReactor(Dispatcher& dispatcher, std::vector<std::string> allowed, std::string who)
      : dispatcher_(dispatcher), link_(std::make_shared<StreamLink>(this)), allowed_(std::move(allowed)),
        who_(std::move(who)) {
    dispatcher_.OnRobotStreamOpened(link_);
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
    if (message->kind == RobotInbound::Kind::kHello && !allowed_.empty() &&
        std::find(allowed_.begin(), allowed_.end(), message->robot_id) == allowed_.end()) {
      dispatcher_.OnRobotGone(link_);
      RequestFinish(Fitted({grpc::StatusCode::PERMISSION_DENIED,
                            who_ + " may not connect as robot '" + engine::Clipped(message->robot_id) + "'"}));
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
  const std::vector<std::string> allowed_;
  const std::string who_;
  pb::RobotMessage in_;
};

// A stream refused before it starts (no token, the wrong role, no client certificate).
class RefusedStream final : public grpc::ServerBidiReactor<pb::RobotMessage, pb::ServerMessage> {
 public:
  explicit RefusedStream(grpc::Status status) { Finish(Fitted(std::move(status))); }
  void OnDone() override { delete this; }
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
    grpc::CallbackServerContext* context) {
  const Authenticator::Outcome auth = AuthorizeCall(auth_, *context, Access::kRobotStream);
  if (!auth.status.ok()) return new RefusedStream(ToGrpcStatus(auth.status));
  std::vector<std::string> allowed;
  std::string who = "this stream";
  if (auth.principal.role == Role::kRobot) {
    allowed.push_back(auth.principal.robot_id);
    who = "token '" + auth.principal.name + "' (robot " + auth.principal.robot_id + ")";
  }
  if (require_certificate_) {
    const std::vector<std::string> names = CertificateNames(*context);
    if (names.empty()) {
      return new RefusedStream({grpc::StatusCode::UNAUTHENTICATED,
                                "robot streams need a client certificate issued by the server's client CA"});
    }
    if (allowed.empty()) {
      allowed = names;
      who = "the client certificate (" + names.front() + ")";
    } else if (std::find(names.begin(), names.end(), allowed.front()) == names.end()) {
      return new RefusedStream({grpc::StatusCode::PERMISSION_DENIED,
                                "the client certificate (" + names.front() + ") is not robot " + allowed.front() +
                                    "'s, whose token this stream carries"});
    }
  }
  return new RobotStreamReactor(dispatcher_, std::move(allowed), std::move(who));
}

MapServiceImpl::MapServiceImpl(const Dispatcher& dispatcher, const Authenticator& auth) : auth_(auth) {
  MapToProto(dispatcher.map(), dispatcher.options().map_version, &map_);
}

grpc::ServerUnaryReactor* MapServiceImpl::GetMap(grpc::CallbackServerContext* context,
                                                 const pb::GetMapRequest* /*request*/,
                                                 pb::GetMapResponse* response) {
  auto* reactor = context->DefaultReactor();
  if (const auto auth = AuthorizeCall(auth_, *context, Access::kReadMap); !auth.status.ok()) {
    reactor->Finish(Fitted(ToGrpcStatus(auth.status)));
    return reactor;
  }
  *response = map_;
  reactor->Finish(grpc::Status::OK);
  return reactor;
}

}  // namespace dispatch::server
