#include "engine/sim/stream_result.h"

namespace dispatch::engine {

const char* AllocationStrategyName(AllocationStrategy strategy) {
  switch (strategy) {
    case AllocationStrategy::kAuction: return "auction";
    case AllocationStrategy::kGreedy: return "greedy";
  }
  return "?";
}

}  // namespace dispatch::engine
