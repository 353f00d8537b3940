#include "server/operator_service.h"

#include "server/grpc_auth.h"
#include "server/grpc_status.h"
#include "server/rest_views.h"

namespace dispatch::server {

grpc::ServerUnaryReactor* OperatorServiceImpl::PauseRobot(grpc::CallbackServerContext* context,
                                                          const pb::RobotCommandRequest* request,
                                                          pb::RobotInfo* response) {
  return Pause(context, request->robot_id(), true, response);
}

grpc::ServerUnaryReactor* OperatorServiceImpl::ResumeRobot(grpc::CallbackServerContext* context,
                                                           const pb::RobotCommandRequest* request,
                                                           pb::RobotInfo* response) {
  return Pause(context, request->robot_id(), false, response);
}

grpc::ServerUnaryReactor* OperatorServiceImpl::Pause(grpc::CallbackServerContext* context,
                                                     const std::string& robot_id, bool paused,
                                                     pb::RobotInfo* response) {
  auto* reactor = context->DefaultReactor();
  const Authenticator::Outcome auth = AuthorizeCall(auth_, *context, Access::kRobotCommand);
  if (!auth.status.ok()) {
    reactor->Finish(Fitted(ToGrpcStatus(auth.status)));
    return reactor;
  }
  if (robot_id.empty()) {
    reactor->Finish({grpc::StatusCode::INVALID_ARGUMENT, "robot_id is required"});
    return reactor;
  }
  dispatcher_.PauseRobot(robot_id, paused, auth.principal.name,
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
