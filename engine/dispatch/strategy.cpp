#include "engine/dispatch/strategy.h"

#include "engine/allocation/auction_allocator.h"
#include "engine/allocation/exact_allocator.h"
#include "engine/allocation/greedy_allocator.h"
#include "engine/allocation/swarm_allocator.h"

namespace dispatch::engine {

std::vector<std::string> AllocatorNames() { return {"auction", "greedy", "exact", "psoga"}; }

Result<std::unique_ptr<Allocator>> MakeAllocator(std::string_view name) {
  std::unique_ptr<Allocator> allocator;
  if (name == "auction") {
    allocator = std::make_unique<AuctionAllocator>();
  } else if (name == "greedy") {
    allocator = std::make_unique<GreedyAllocator>();
  } else if (name == "exact") {
    allocator = std::make_unique<ExactAllocator>();
  } else if (name == "psoga") {
    allocator = std::make_unique<SwarmAllocator>();
  } else {
    std::string known;
    for (const auto& n : AllocatorNames()) known += (known.empty() ? "" : " | ") + n;
    return InvalidArgument("unknown strategy '" + std::string(name) + "' (" + known + ")");
  }
  return allocator;
}

}  // namespace dispatch::engine
