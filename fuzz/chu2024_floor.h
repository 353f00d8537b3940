// The Chu2024 floor and its route table for the harnesses that run the service's checks on
// a real floor, built once before the first input (LLVMFuzzerInitialize: a route table takes
// seconds under the sanitizers, which is no input's time). One harness per executable
// includes this header.
#pragma once

#include <memory>

#include "engine/map/chu2024_floor.h"
#include "engine/routing/route_table.h"
#include "fuzz/fuzz_input.h"

namespace dispatch::fuzz {

struct Floor {
  std::shared_ptr<const engine::WarehouseMap> map;
  std::shared_ptr<const engine::RouteTable> routes;
};

inline const Floor* the_floor = nullptr;

inline const Floor& TheFloor() { return *the_floor; }

}  // namespace dispatch::fuzz

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  auto* f = new dispatch::fuzz::Floor();
  f->map = std::make_shared<const dispatch::engine::WarehouseMap>(dispatch::engine::BuildChu2024Floor().value());
  f->routes = std::shared_ptr<const dispatch::engine::RouteTable>(dispatch::engine::MakeRouteTable(f->map, {}).value());
  dispatch::fuzz::the_floor = f;
  return 0;
}
