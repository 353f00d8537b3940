// BIT2024's PSO-GA as an allocation strategy ("psoga", issue 17 §1): the single orders of a
// batch (an allocation round's pending orders) are allocated jointly by PlanSwarm (seed 003
// steps 1-5, swarm_allocation.h), each robot's share in the plan's execution order.
//
// - A task is an order: it starts at its first pick and moves the robot to its drop, its
//   length the route table's drive time from pick to drop; the distances of eq. (1) are the
//   route table's drive times (the seed's A* costs; time and distance differ by the speed).
//   Orders carry no heading, so f_switch is 0.
// - The robots searched are, for each order, the `candidates` with room in their queue that
//   can start it soonest (their queue's end time plus the drive to its first pick): a batch of
//   a few orders in a large fleet is searched over tens of robots, not the whole fleet. A
//   robot starts from where its queue ends.
// - Formation orders (the seed allocates single robots) go to the auction, in the batch's
//   order and before the singles; so does a single the plan cannot place (a queue found full
//   when the plan is committed).
// Deterministic (a fixed seed; the deadline, if `budget` ends the search, is the one source
// of variation). Not thread-safe, like every Allocator.
#pragma once

#include <chrono>
#include <cstddef>
#include <string_view>
#include <vector>

#include "engine/allocation/allocator.h"
#include "engine/allocation/auction_allocator.h"
#include "engine/allocation/swarm_allocation.h"

namespace dispatch::engine {

class SwarmAllocator : public Allocator {
 public:
  explicit SwarmAllocator(SwarmOptions options = {}, std::size_t candidates = 3,
                          std::chrono::milliseconds budget = std::chrono::milliseconds(1000));
  std::string_view name() const override { return SwarmMethodName(options_.method); }
  // A batch of one order.
  Result<AwardExplanation> Allocate(const Order& order, FleetState& state) override;
  void AllocateBatch(const std::vector<const Order*>& orders, FleetState& state,
                     const AwardSink& sink) override;

 private:
  SwarmOptions options_;
  std::size_t candidates_;
  std::chrono::milliseconds budget_;
  AuctionAllocator auction_;
};

}  // namespace dispatch::engine
