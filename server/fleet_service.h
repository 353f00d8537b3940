// FleetService.Connect (proto/warehouse/dispatch/v1/fleet.proto) on gRPC's callback API: one
// ServerBidiReactor per robot stream, so thousands of robots need no thread each. Every
// robot message goes to the dispatcher loop as a RobotInbound; the loop answers through the
// stream's RobotLink (queued writes, see queued_writer.h). Thread-safe.
#pragma once

#include "server/dispatcher.h"
#include "warehouse/dispatch/v1/fleet.grpc.pb.h"
#include "warehouse/dispatch/v1/map.grpc.pb.h"

namespace dispatch::server {

class FleetServiceImpl final : public ::warehouse::dispatch::v1::FleetService::CallbackService {
 public:
  explicit FleetServiceImpl(Dispatcher& dispatcher) : dispatcher_(dispatcher) {}
  grpc::ServerBidiReactor<::warehouse::dispatch::v1::RobotMessage,
                          ::warehouse::dispatch::v1::ServerMessage>*
  Connect(grpc::CallbackServerContext* context) override;

 private:
  Dispatcher& dispatcher_;
};

// MapService.GetMap: the map the dispatcher runs on, built once.
class MapServiceImpl final : public ::warehouse::dispatch::v1::MapService::CallbackService {
 public:
  explicit MapServiceImpl(const Dispatcher& dispatcher);
  grpc::ServerUnaryReactor* GetMap(grpc::CallbackServerContext* context,
                                   const ::warehouse::dispatch::v1::GetMapRequest* request,
                                   ::warehouse::dispatch::v1::GetMapResponse* response) override;

 private:
  ::warehouse::dispatch::v1::GetMapResponse map_;
};

}  // namespace dispatch::server
