// Every gRPC request message the service takes, as bytes, through its converters and checks:
// the first byte picks the message (SubmitOrderRequest through OrderRequestFromProto and the
// core's AdmitOrder on the Chu2024 floor; ListOrdersRequest's states; the robot stream's
// RobotMessage through RobotInboundFromProto and, for a Hello, the robot's checks).
#include "engine/dispatch/order_intake.h"
#include "engine/dispatch/robot_intake.h"
#include "fuzz/chu2024_floor.h"
#include "server/proto_convert.h"
#include "warehouse/dispatch/v1/fleet.pb.h"
#include "warehouse/dispatch/v1/operator.pb.h"
#include "warehouse/dispatch/v1/orders.pb.h"

namespace pb = ::warehouse::dispatch::v1;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const dispatch::fuzz::Floor& f = dispatch::fuzz::TheFloor();
  if (size == 0) return 0;
  const int which = data[0] % 4;
  const auto* bytes = data + 1;
  const int n = static_cast<int>(size - 1);
  switch (which) {
    case 0: {
      pb::SubmitOrderRequest r;
      if (!r.ParseFromArray(bytes, n)) return 0;
      auto converted = dispatch::server::OrderRequestFromProto(r);
      if (converted.ok()) (void)dispatch::engine::AdmitOrder(*f.map, *f.routes, *converted, {}, "ord-fuzz");
      return 0;
    }
    case 1: {
      pb::ListOrdersRequest r;
      if (!r.ParseFromArray(bytes, n)) return 0;
      for (int s : r.states()) (void)dispatch::server::OrderStateFromProto(static_cast<pb::OrderState>(s));
      return 0;
    }
    case 2: {
      pb::RobotMessage r;
      if (!r.ParseFromArray(bytes, n)) return 0;
      auto in = dispatch::server::RobotInboundFromProto(r);
      if (in.ok() && in->kind == dispatch::server::RobotInbound::Kind::kHello) {
        (void)dispatch::engine::LocateRobot(*f.map, in->robot_id, in->pose, 1.0);
      }
      return 0;
    }
    default: {
      pb::CancelOrderRequest cancel;
      (void)cancel.ParseFromArray(bytes, n);
      pb::RobotCommandRequest command;
      (void)command.ParseFromArray(bytes, n);
      pb::WatchOrdersRequest watch;
      (void)watch.ParseFromArray(bytes, n);
      return 0;
    }
  }
}
