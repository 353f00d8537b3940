// What the batch strategies (exact_allocator.h, swarm_allocator.h) share: a batch's single
// orders with their tasks, the formations and the orders that cannot be allocated at all
// having gone to the sink on the way; the robots that can start an order soonest; and one
// order allocated as a batch of one.
#pragma once

#include <cstddef>
#include <vector>

#include "engine/allocation/allocator.h"

namespace dispatch::engine {

struct BatchSingles {
  std::vector<const Order*> orders;  // in batch order
  std::vector<PlanTask> tasks;       // orders[k]'s task
};

// Formation orders and orders asking for a stop heading (only four-wheel-steer robots can
// serve them, FleetState::CanServe) go to `formations` (the auction) and their awards to
// `sink`, in batch order; so do PrepareOrder's errors. The rest are returned.
BatchSingles TakeSingles(const std::vector<const Order*>& orders, FleetState& state,
                         Allocator& formations, const AwardSink& sink);

// The `count` robots with room in their queue that can start `task` soonest (their queue's
// end time plus the drive to its first pick; ties to the lower index), ascending by index.
// Empty when no robot with room reaches its first pick.
std::vector<std::size_t> SoonestRobots(const FleetState& state, const PlanTask& task, std::size_t count);

// `order` alone through `batch`'s AllocateBatch.
Result<AwardExplanation> AllocateAsBatch(Allocator& batch, const Order& order, FleetState& state);

}  // namespace dispatch::engine
