#include "server/operator_service.h"

#include "server/grpc_auth.h"
#include "server/grpc_status.h"
#include "server/rest_views.h"

namespace dispatch::server {

using engine::RobotCommandKind;

grpc::ServerUnaryReactor* OperatorServiceImpl::PauseRobot(grpc::CallbackServerContext* c, const Request* r, Info* out) {
  return Command(c, RobotCommandKind::kPause, r->robot_id(), "", out);
}

grpc::ServerUnaryReactor* OperatorServiceImpl::ResumeRobot(grpc::CallbackServerContext* c, const Request* r,
                                                           Info* out) {
  return Command(c, RobotCommandKind::kResume, r->robot_id(), "", out);
}

grpc::ServerUnaryReactor* OperatorServiceImpl::TakeOutOfService(grpc::CallbackServerContext* c, const Request* r,
                                                                Info* out) {
  return Command(c, RobotCommandKind::kTakeOutOfService, r->robot_id(), "", out);
}

grpc::ServerUnaryReactor* OperatorServiceImpl::ReturnToService(grpc::CallbackServerContext* c, const Request* r,
                                                               Info* out) {
  return Command(c, RobotCommandKind::kReturnToService, r->robot_id(), "", out);
}

grpc::ServerUnaryReactor* OperatorServiceImpl::ClearRobot(grpc::CallbackServerContext* c, const Request* r, Info* out) {
  return Command(c, RobotCommandKind::kClear, r->robot_id(), "", out);
}

grpc::ServerUnaryReactor* OperatorServiceImpl::SendRobot(grpc::CallbackServerContext* c,
                                                         const ::warehouse::dispatch::v1::SendRobotRequest* r,
                                                         Info* out) {
  return Command(c, RobotCommandKind::kSend, r->robot_id(), r->station(), out);
}

grpc::ServerUnaryReactor* OperatorServiceImpl::Command(grpc::CallbackServerContext* context, RobotCommandKind kind,
                                                       const std::string& robot_id, const std::string& station,
                                                       Info* response) {
  auto* reactor = context->DefaultReactor();
  const Authenticator::Outcome auth = AuthorizeCall(auth_, *context, Access::kRobotCommand);
  if (!auth.status.ok()) {
    reactor->Finish(Fitted(ToGrpcStatus(auth.status)));
    return reactor;
  }
  if (robot_id.empty() || (kind == RobotCommandKind::kSend && station.empty())) {
    reactor->Finish({grpc::StatusCode::INVALID_ARGUMENT, robot_id.empty() ? "robot_id is required" : "station is required"});
    return reactor;
  }
  dispatcher_.CommandRobot(kind, robot_id, station, auth.principal.name,
                           [this, reactor, response, robot_id](ServiceStatus status) {
                             if (status.ok()) {
                               auto snap = dispatcher_.snapshot();
                               if (auto it = snap->robots.find(robot_id); it != snap->robots.end()) {
                                 RobotToProto(it->second, dispatcher_.map(), response);
                               }
                             }
                             reactor->Finish(Fitted(ToGrpcStatus(status)));
                           });
  return reactor;
}

}  // namespace dispatch::server
