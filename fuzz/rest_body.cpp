// REST bodies (server/rest_views.h FromJson, the proto3 JSON mapping) of POST /api/v1/orders
// through the service's conversion and the dispatch core's order intake (AdmitOrder) on the
// Chu2024 floor: any body gives an order or an error.
#include "engine/dispatch/order_intake.h"
#include "engine/map/chu2024_floor.h"
#include "fuzz/fuzz_input.h"
#include "server/proto_convert.h"
#include "server/rest_views.h"

namespace {

struct Floor {
  std::shared_ptr<const dispatch::engine::WarehouseMap> map;
  std::shared_ptr<const dispatch::engine::RouteTable> routes;
  Floor() {
    map = std::make_shared<const dispatch::engine::WarehouseMap>(dispatch::engine::BuildChu2024Floor().value());
    routes = std::shared_ptr<const dispatch::engine::RouteTable>(dispatch::engine::MakeRouteTable(map, {}).value());
  }
};

}  // namespace

// Built once, before the first input (a route table takes seconds under the sanitizers: not
// a unit's time).
const Floor* the_floor = nullptr;

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  the_floor = new Floor();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const Floor& f = *the_floor;
  ::warehouse::dispatch::v1::SubmitOrderRequest request;
  if (!dispatch::server::FromJson(std::string(dispatch::fuzz::Text(data, size)), &request).ok()) return 0;
  auto converted = dispatch::server::OrderRequestFromProto(request);
  if (!converted.ok()) return 0;
  (void)dispatch::engine::AdmitOrder(*f.map, *f.routes, *converted, {}, "ord-fuzz");
  return 0;
}
