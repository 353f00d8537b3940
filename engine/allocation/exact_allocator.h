// The exact assignment as an allocation strategy ("exact", issue 17 §1, SPEC §3.2 "an exact
// optimal assignment for small batches"): the single orders of a batch (an allocation round's
// pending orders) go to the robots by the minimum of a batch cost (optimal_assignment.h), found
// by enumerating every map; each robot serves its new orders after its queue in batch order.
// The cost is by default the bid sum: for every order, Chu2024 eq. (1) of its robot's queue up
// to it, the auction's bid without the traffic term, so the strategy is the auction's criterion
// optimised over the whole batch instead of order by order. (The queue totals, the yardstick of
// the auction's tests, measure distance driven and work and nothing of waiting: on bursts they
// pile orders on a few robots.)
//
// Exact within stated bounds, so that a round stays small whatever the fleet:
// - The robots an order may go to are its `candidates` with room that can start it soonest
//   (their queue's end time plus the drive to its first pick), as for PSO-GA.
// - The batch is cut, in its order, into chunks whose maps (robots of the chunk ^ orders of
//   the chunk) stay within `max_maps` and whose robots have a free queue place for each of
//   its orders (AllocationConfig::max_queue); each chunk is the exact optimum over its robots given
//   the chunks committed before it. A batch that fits one chunk, in a fleet no larger than
//   `candidates`, gets the global optimum of BatchCost.
// - Formation orders, orders no robot with room reaches, a chunk with no finite map (full
//   queues, one-way lanes) and, once `budget` is spent, the rest of the batch go to the
//   auction, which says why.
// - With AllocationConfig::max_queue = 1 every robot with room takes one order at most, and the
//   round is one assignment problem: OneToOneAssignment over the whole batch and every robot
//   with room (the Hungarian method), up to `max_one_to_one_work` (beyond, the chunks). When
//   the orders outnumber those robots, the cheapest to serve are served (a robot near a pick
//   takes it; the LoRR benchmark's setting), and the others wait for the next round, saying so.
// The traffic term of the auction's bids is not part of BatchCost. Deterministic unless the
// budget runs out. Not thread-safe, like every Allocator.
#pragma once

#include <chrono>
#include <cstddef>
#include <string_view>
#include <vector>

#include "engine/allocation/allocator.h"
#include "engine/allocation/auction_allocator.h"
#include "engine/allocation/optimal_assignment.h"

namespace dispatch::engine {

struct ExactOptions {
  BatchObjective objective = BatchObjective::kBidSum;
  std::size_t candidates = 4;                          // robots per order (>= 1)
  std::size_t max_maps = 50'000;                       // maps per chunk (>= candidates)
  std::chrono::milliseconds budget{1000};              // per batch
  // The one-to-one round's bound: min(orders, robots)^2 x max(orders, robots) (the Hungarian
  // method's steps; 2e8 is about half a second here). Larger rounds go in chunks.
  double max_one_to_one_work = 2e8;
};

class ExactAllocator : public Allocator {
 public:
  explicit ExactAllocator(ExactOptions options = {});
  std::string_view name() const override { return "exact"; }
  // A batch of one order.
  Result<AwardExplanation> Allocate(const Order& order, FleetState& state) override;
  void AllocateBatch(const std::vector<const Order*>& orders, FleetState& state,
                     const AwardSink& sink) override;

 private:
  // Every robot holds at most one order (max_queue = 1): the round is one-to-one over
  // `robots`, those with room.
  void AllocateOneToOne(const std::vector<const Order*>& singles, const std::vector<PlanTask>& tasks,
                        const std::vector<std::size_t>& robots, FleetState& state, const AwardSink& sink);
  // Appends `order` to `robot`'s queue and tells `sink` why (`what`, the batch's cost).
  void Commit(const Order& order, const PlanTask& task, std::size_t robot, const char* what, double batch_cost,
              FleetState& state, const AwardSink& sink) const;

  ExactOptions options_;
  AuctionAllocator auction_;
};

}  // namespace dispatch::engine
