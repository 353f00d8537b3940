// OperatorService (proto/warehouse/dispatch/v1/operator.proto, issue 18 §4): operators'
// commands on robots over gRPC, the same as REST's POST /api/v1/robots/{id}/pause | /resume.
// Every call needs a token that may send robot commands (operator, admin). Thread-safe.
#pragma once

#include "server/auth.h"
#include "server/dispatcher.h"
#include "warehouse/dispatch/v1/operator.grpc.pb.h"

namespace dispatch::server {

class OperatorServiceImpl final : public ::warehouse::dispatch::v1::OperatorService::CallbackService {
 public:
  OperatorServiceImpl(Dispatcher& dispatcher, const Authenticator& auth) : dispatcher_(dispatcher), auth_(auth) {}
  grpc::ServerUnaryReactor* PauseRobot(grpc::CallbackServerContext* context,
                                       const ::warehouse::dispatch::v1::RobotCommandRequest* request,
                                       ::warehouse::dispatch::v1::RobotInfo* response) override;
  grpc::ServerUnaryReactor* ResumeRobot(grpc::CallbackServerContext* context,
                                        const ::warehouse::dispatch::v1::RobotCommandRequest* request,
                                        ::warehouse::dispatch::v1::RobotInfo* response) override;

 private:
  grpc::ServerUnaryReactor* Pause(grpc::CallbackServerContext* context, const std::string& robot_id, bool paused,
                                  ::warehouse::dispatch::v1::RobotInfo* response);
  Dispatcher& dispatcher_;
  const Authenticator& auth_;
};

}  // namespace dispatch::server
