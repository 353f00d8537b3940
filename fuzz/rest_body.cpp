// REST bodies (server/rest_views.h FromJson, the proto3 JSON mapping) of POST /api/v1/orders
// through the service's conversion and the dispatch core's order intake (AdmitOrder) on the
// Chu2024 floor: any body gives an order or an error.
#include "engine/dispatch/order_intake.h"
#include "fuzz/chu2024_floor.h"
#include "server/proto_convert.h"
#include "server/rest_views.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const dispatch::fuzz::Floor& f = dispatch::fuzz::TheFloor();
  ::warehouse::dispatch::v1::SubmitOrderRequest request;
  if (!dispatch::server::FromJson(std::string(dispatch::fuzz::Text(data, size)), &request).ok()) return 0;
  auto converted = dispatch::server::OrderRequestFromProto(request);
  if (!converted.ok()) return 0;
  (void)dispatch::engine::AdmitOrder(*f.map, *f.routes, *converted, {}, "ord-fuzz");
  return 0;
}
