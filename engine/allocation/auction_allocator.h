// The auction with traffic-flow prediction (Chu2024 §2.1-2.3, eqs. (1)-(8); SPEC §3.2).
//
// Every robot bids for the order appended to its queue:
//   T_d = (queue travel time) + (leg from the queue's end to the first pick) + (the order's
//         own route pick -> ... -> drop), all from the route table's Floyd costs (= S_d / v);
//   T_w = n_c * t_w over the whole queue and the order (n_c = picks + drop, eq. (3));
//   T_t = T_d + T_w (eq. (2));  F = sum_p N_p,max / S_p over the order's candidate route,
//   sampled every h metres (RouteSampler) at the times the robot would be there, counting
//   the other robots' predicted positions (eqs. (6)-(8));  B = alpha T_t + beta T_d + zeta F
//   (eqs. (4), (5)).
// The candidate route starts where and when the robot's queue ends. F is computed for every
// robot (no pruning), so the explanation holds every robot's full terms.
// Lowest B wins; ties go to the earlier robot in FleetState order.
//
// Formation orders (§2.2): the lowest bidder leads; then every other robot's cost to reach the
// first pick is B' = alpha T_t' + beta T_d' + zeta F' with T_d' = queue travel + leg to the
// first pick, T_w' = the queue's work time (the formation's own work is not yet done there),
// F' over the leg's samples and the first pick on arrival; the two lowest B' join (ties by
// robot order). Robots that cannot reach the first pick bid +infinity and never win.
//
// Not thread-safe (scratch buffers are reused between calls to avoid per-robot allocation).
#pragma once

#include <string_view>
#include <vector>

#include "engine/allocation/allocator.h"
#include "engine/allocation/traffic_prediction.h"

namespace dispatch::engine {

class AuctionAllocator final : public Allocator {
 public:
  std::string_view name() const override { return "auction"; }
  Result<AwardExplanation> Allocate(const Order& order, FleetState& state) override;

  // Every robot's bid for `task` appended to its queue, in robot order; commits nothing.
  std::vector<Bid> ComputeBids(const FleetState& state, const PlanTask& task);
  // Every robot's cost to reach `first_pick` after its queue, in robot order; commits nothing.
  std::vector<Bid> ComputeReachBids(const FleetState& state, PointId first_pick);

 private:
  std::vector<RouteSample> shared_;   // the order's samples from its first pick, from t = 0
  std::vector<ZoneId> shared_zones_;  // ZoneAt of each shared_ sample
  std::vector<RouteSample> samples_;  // one robot's candidate route
};

}  // namespace dispatch::engine
