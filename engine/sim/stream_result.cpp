#include "engine/sim/stream_result.h"

namespace dispatch::engine {

const char* AllocationStrategyName(AllocationStrategy strategy) {
  switch (strategy) {
    case AllocationStrategy::kAuction: return "auction";
    case AllocationStrategy::kGreedy: return "greedy";
    case AllocationStrategy::kExact: return "exact";
    case AllocationStrategy::kPsoGa: return "psoga";
  }
  return "?";
}

std::optional<AllocationStrategy> ParseAllocationStrategy(std::string_view name) {
  for (AllocationStrategy s : {AllocationStrategy::kAuction, AllocationStrategy::kGreedy, AllocationStrategy::kExact,
                              AllocationStrategy::kPsoGa}) {
    if (name == AllocationStrategyName(s)) return s;
  }
  return std::nullopt;
}

}  // namespace dispatch::engine
