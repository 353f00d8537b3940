// OperatorService (proto/warehouse/dispatch/v1/operator.proto, issue 18 §4): operators'
// commands on robots over gRPC, the same as REST's POST /api/v1/robots/{id}/pause | /resume |
// /out-of-service | /return-to-service | /clear | /send.
// Every call needs a token that may send robot commands (operator, admin). Thread-safe.
#pragma once

#include "server/auth.h"
#include "server/dispatcher.h"
#include "warehouse/dispatch/v1/operator.grpc.pb.h"

namespace dispatch::server {

class OperatorServiceImpl final : public ::warehouse::dispatch::v1::OperatorService::CallbackService {
 public:
  OperatorServiceImpl(Dispatcher& dispatcher, const Authenticator& auth) : dispatcher_(dispatcher), auth_(auth) {}
  using Request = ::warehouse::dispatch::v1::RobotCommandRequest;
  using Info = ::warehouse::dispatch::v1::RobotInfo;
  grpc::ServerUnaryReactor* PauseRobot(grpc::CallbackServerContext* c, const Request* r, Info* out) override;
  grpc::ServerUnaryReactor* ResumeRobot(grpc::CallbackServerContext* c, const Request* r, Info* out) override;
  grpc::ServerUnaryReactor* TakeOutOfService(grpc::CallbackServerContext* c, const Request* r, Info* out) override;
  grpc::ServerUnaryReactor* ReturnToService(grpc::CallbackServerContext* c, const Request* r, Info* out) override;
  grpc::ServerUnaryReactor* ClearRobot(grpc::CallbackServerContext* c, const Request* r, Info* out) override;
  grpc::ServerUnaryReactor* SendRobot(grpc::CallbackServerContext* c,
                                      const ::warehouse::dispatch::v1::SendRobotRequest* r, Info* out) override;

 private:
  grpc::ServerUnaryReactor* Command(grpc::CallbackServerContext* context, engine::RobotCommandKind kind,
                                    const std::string& robot_id, const std::string& station, Info* response);
  Dispatcher& dispatcher_;
  const Authenticator& auth_;
};

}  // namespace dispatch::server
