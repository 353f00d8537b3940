// Exact optimal assignment of a small batch of single-robot orders: the yardstick for the
// auction (SPEC §3.2 "an exact optimal assignment for small batches").
//
// Batch cost of a map order -> robot (each robot serves its new orders after its current
// queue, in batch order): the sum over ALL robots of Chu2024 eq. (1),
// alpha * T_t,i + beta * T_d,i, of the final queues, with T_d from route-table costs and
// T_w = n_c * t_w exactly as the auction's bids (the traffic term is not part of it). Robots
// without new orders contribute their current queue's constant cost.
//
// The bid sum (BatchObjective::kBidSum) instead adds, for every order of the batch, the bid
// the auction would see for it in that map: eq. (1) of its robot's queue up to and including
// it (again without the traffic term). It counts a robot's earlier orders again for every
// order queued behind them, so, like the auction's bids, it spreads orders over the robots
// (the queue totals are lowest when the fewest robots drive).
//
//  - BruteForceAssignment: the minimum over all robot_count^order_count maps (optionally only
//    injective ones, only onto a subset of the robots, only within each robot's free queue
//    places); ties go to the first map in lexicographic order of robot indices.
//  - HungarianAssignment: the one-order-per-robot case (orders <= robots) in O(n^2 m) on the
//    marginal cost matrix; equals BruteForceAssignment with one_order_per_robot.
// Formation orders are rejected (kInvalidArgument). Pure functions of the FleetState (read
// only); thread-safe for concurrent const use of one state.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "engine/allocation/fleet_state.h"
#include "engine/common/result.h"
#include "engine/fleet/order.h"

namespace dispatch::engine {

enum class BatchObjective { kQueueTotals, kBidSum };

struct BatchAssignment {
  std::vector<std::size_t> robot_of_order;  // per order, in batch order: a robot index
  double cost = 0.0;                        // BatchCost of that map (the objective's)
};

struct OptimalAssignmentOptions {
  BatchObjective objective = BatchObjective::kQueueTotals;
  bool one_order_per_robot = false;
  // The robots orders may go to (indices, ascending, no repeats); empty: all of them.
  std::vector<std::size_t> robots;
  // Give a robot no more orders than its queue has free places (AllocationConfig::max_queue).
  bool respect_queue_room = false;
  // Brute force refuses (kFailedPrecondition) batches with more maps than this.
  std::size_t max_maps = 1'000'000;
  // Polled every 4,096 maps; true ends the search with kFailedPrecondition (a deadline or a
  // cancel: PlanLimits' DeadlineCheck builds one).
  std::function<bool()> stop;
};

// The batch cost of `robot_of_order` (+infinity if some robot cannot reach its order).
// Errors: bad orders (see PrepareOrder), formation orders, size mismatch, unknown robot.
Result<double> BatchCost(const FleetState& state, const std::vector<Order>& orders,
                         const std::vector<std::size_t>& robot_of_order,
                         BatchObjective objective = BatchObjective::kQueueTotals);

// Errors as BatchCost, plus kUnreachable when no map has a finite cost.
Result<BatchAssignment> BruteForceAssignment(const FleetState& state,
                                             const std::vector<Order>& orders,
                                             const OptimalAssignmentOptions& options = {});

// Errors as BatchCost, plus kFailedPrecondition if orders > robots, kUnreachable if no
// injective map has a finite cost.
Result<BatchAssignment> HungarianAssignment(const FleetState& state,
                                            const std::vector<Order>& orders);

// robot_of_order's entry for an order a one-to-one assignment leaves out.
inline constexpr std::size_t kNoRobot = static_cast<std::size_t>(-1);

// The one-order-per-robot case of any shape, over `robots` (indices): as many orders as there
// are robots (or robots as orders) each go to a distinct robot, at the least total of the
// marginal costs (HungarianAssignment's: eq. (1) of the order appended to the robot's queue),
// by the Hungarian method on the smaller side (O(min^2 max)). The orders left out, and an
// order matched to a robot that cannot reach it, get kNoRobot. cost = the matched orders'
// marginal costs summed. Errors as BatchCost, or an unknown robot index.
Result<BatchAssignment> OneToOneAssignment(const FleetState& state, const std::vector<Order>& orders,
                                           const std::vector<std::size_t>& robots);

}  // namespace dispatch::engine
