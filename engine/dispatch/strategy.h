// Allocation strategies by name (issue 15 §1): the one registry the service, the simulators and
// the benchmarks select from, so that a configuration names the same strategy everywhere.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "engine/allocation/allocator.h"
#include "engine/common/result.h"

namespace dispatch::engine {

// The names MakeAllocator knows, in the order help texts list them.
std::vector<std::string> AllocatorNames();
// A fresh strategy: "auction" (Chu2024 §2, bids with traffic prediction), "greedy" (nearest
// idle robot), "exact" (the minimum batch cost over every map of each round's single orders, in
// chunks of bounded size, exact_allocator.h) or "psoga" (BIT2024's PSO-GA over each round's
// single orders as one batch); the batch strategies leave formations to the auction. kInvalidArgument naming the known ones for any other name.
Result<std::unique_ptr<Allocator>> MakeAllocator(std::string_view name);

}  // namespace dispatch::engine
