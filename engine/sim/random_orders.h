// Seeded random order streams for the simulators, benchmarks and liveness tests.
//
// Order i (id "O<i+1>") picks at one uniformly drawn pick point and drops at one uniformly
// drawn drop point (distinct points), is a formation order (3 robots) with probability
// `formation_share` and a single-robot order otherwise, has t_w = `work_time`, and is
// released at i * `interval` plus a uniform jitter in [0, interval) (a steady stream; jitter
// 0 gives exact spacing). created_time = release time. Random numbers come from
// std::mt19937_64 drawn through our own integer/real mapping, so a seed gives the same stream
// on every platform. Errors: a map without pick or drop points, a bad interval, work time or
// formation share.
// Pure function; thread-safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "engine/common/result.h"
#include "engine/fleet/order.h"
#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

struct RandomOrderOptions {
  std::size_t count = 200;
  std::uint64_t seed = 1;
  double interval = 2.0;   // s between releases (>= 0)
  bool jitter = true;      // uniform jitter within each interval
  double work_time = kDefaultWorkTime;
  double formation_share = 0.0;  // [0, 1]: the expected fraction of formation orders
};

Result<std::vector<Order>> RandomOrders(const WarehouseMap& map, const RandomOrderOptions& options);

}  // namespace dispatch::engine
