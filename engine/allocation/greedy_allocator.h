// Greedy nearest-idle baseline (Wang2019's rule; SPEC §3.2 "other strategies").
//
// A robot is idle when its queue in the FleetState is empty. The order goes to the idle robot
// with the least travel time from where it stands to the first pick (route-table cost); if
// no robot is idle, to the robot whose queue ends earliest, then the nearest from its queue's
// end. Formations take the first 3 robots by the same ranking (leader = first). Ties: robot
// order. No traffic term, no queue totals.
//
// Explanation: Bid::bid = t_d = the travel time to the first pick from the queue's end,
// ready_time = when the queue ends; t_w, t_t, flow and x are 0 (not used by this rule).
// Unreachable robots have reachable = false and bid +infinity. Stateless; thread-compatible.
#pragma once

#include <string_view>

#include "engine/allocation/allocator.h"

namespace dispatch::engine {

class GreedyAllocator final : public Allocator {
 public:
  std::string_view name() const override { return "greedy-nearest-idle"; }
  Result<AwardExplanation> Allocate(const Order& order, FleetState& state) override;
};

}  // namespace dispatch::engine
