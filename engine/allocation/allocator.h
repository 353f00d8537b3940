// The allocation strategy interface (SPEC §3.2: "other strategies, same interface") and the
// batch driver that auctions orders in priority-then-arrival order (Chu2024 §2.1 step 1).
//
// Allocate() decides the robot(s) for one order and commits the award to the FleetState
// (queues, plans, traffic prediction). On error it leaves the state unchanged, so later
// orders still allocate. Strategies are deterministic: equal inputs give equal awards.
// Not thread-safe: an Allocator and its FleetState are used by one thread at a time.
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "engine/allocation/bid.h"
#include "engine/allocation/fleet_state.h"
#include "engine/common/result.h"
#include "engine/fleet/order.h"

namespace dispatch::engine {

// Receives each order's award (or why it was not allocated) of a batch as soon as it is
// committed to the FleetState, before the next one is made.
using AwardSink = std::function<void(const Order& order, Result<AwardExplanation> award)>;

class Allocator {
 public:
  virtual ~Allocator() = default;
  virtual std::string_view name() const = 0;
  virtual Result<AwardExplanation> Allocate(const Order& order, FleetState& state) = 0;
  // A batch (an allocation round's orders, in priority-then-arrival order). By default one
  // order at a time in the given order; a batch strategy (PSO-GA) decides them jointly and
  // may commit them in another order. Every order reaches `sink` exactly once.
  virtual void AllocateBatch(const std::vector<const Order*>& orders, FleetState& state,
                             const AwardSink& sink);
};

// Checks that `order` can be allocated at all and returns its task (t_w per the config).
// Errors name the order: kInvalidArgument (no picks, bad work time), kNotFound (unknown point
// id), kUnreachable (a pick or the drop cannot be reached along the order: pick k -> pick
// k+1 -> drop), kFailedPrecondition (a formation order with fewer than 3 robots).
// Whether some robot reaches the first pick is left to the strategy.
Result<PlanTask> PrepareOrder(const Order& order, const FleetState& state);

struct OrderAllocation {
  std::string order_id;
  Result<AwardExplanation> award;
};

// Sorts the orders by (priority descending, created_time, id) and allocates them as one
// batch (Allocator::AllocateBatch), continuing after errors. Results in allocation order.
std::vector<OrderAllocation> AllocateAll(Allocator& allocator, std::vector<Order> orders,
                                         FleetState& state);

}  // namespace dispatch::engine
