// FleetService.Connect (proto/warehouse/dispatch/v1/fleet.proto) on gRPC's callback API: one
// ServerBidiReactor per robot stream, so thousands of robots need no thread each. Every
// robot message goes to the dispatcher loop as a RobotInbound; the loop answers through the
// stream's RobotLink (queued writes, see queued_writer.h). Thread-safe.
//
// Identity (issue 18 §2-3): a stream needs a token that may connect as a robot; a robot
// token's stream may say Hello only as its own robot id, and with `require_certificate`
// (--tls-client-ca) every stream must come with a verified client certificate naming the
// robot id of its Hello. A Hello as anyone else ends the stream (PERMISSION_DENIED) before the
// dispatcher sees it, so the real robot's plan and orders are untouched.
#pragma once

#include "server/auth.h"
#include "server/dispatcher.h"
#include "warehouse/dispatch/v1/fleet.grpc.pb.h"
#include "warehouse/dispatch/v1/map.grpc.pb.h"

namespace dispatch::server {

class FleetServiceImpl final : public ::warehouse::dispatch::v1::FleetService::CallbackService {
 public:
  FleetServiceImpl(Dispatcher& dispatcher, const Authenticator& auth, bool require_certificate)
      : dispatcher_(dispatcher), auth_(auth), require_certificate_(require_certificate) {}
  grpc::ServerBidiReactor<::warehouse::dispatch::v1::RobotMessage,
                          ::warehouse::dispatch::v1::ServerMessage>*
  Connect(grpc::CallbackServerContext* context) override;

 private:
  Dispatcher& dispatcher_;
  const Authenticator& auth_;
  const bool require_certificate_;
};

// MapService.GetMap: the map the dispatcher runs on, built once.
class MapServiceImpl final : public ::warehouse::dispatch::v1::MapService::CallbackService {
 public:
  MapServiceImpl(const Dispatcher& dispatcher, const Authenticator& auth);
  grpc::ServerUnaryReactor* GetMap(grpc::CallbackServerContext* context,
                                   const ::warehouse::dispatch::v1::GetMapRequest* request,
                                   ::warehouse::dispatch::v1::GetMapResponse* response) override;

 private:
  ::warehouse::dispatch::v1::GetMapResponse map_;
  const Authenticator& auth_;
};

}  // namespace dispatch::server
