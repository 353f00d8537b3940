// Wang2019's path heat (seed 004 §3.1, eqs. (13)-(14)): lanes that many planned routes use in
// the coming period weigh more, so the next routes spread over the floor instead of queueing on
// the shortest lanes. The seed's five steps: (1) every robot's route by plain Dijkstra;
// (2) the use h_k of each lane in the period δ; (3) the robots b_g on each lane; (4)
//   F_k = (b_k + 1) · h_k / Σ_j b_j · h_j,      (13)
//   w_k = 1 + F_k;                              (14)
// (5) the routes again by Dijkstra over length · w.
//
// Read here (the seed's symbols are partly lost in its text): a lane is a map path (both
// directions of a bidirectional lane are one lane), h_k counts the traversals of lane k that
// start within [from, from + period], and b_k the distinct robots making them. With no use at
// all (Σ = 0) every weight is 1 and routes are the plain shortest ones.
// Immutable once built; safe to share.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "engine/common/result.h"
#include "engine/map/warehouse_map.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine {

// One planned traversal of an arc by a robot, starting at `time`.
struct LaneUse {
  ArcId arc = -1;
  int robot = -1;
  double time = 0.0;
};

class PathHeat {
 public:
  // Uses outside [from, from + period] or on unknown arcs are ignored.
  static PathHeat FromUses(const WarehouseMap& map, const std::vector<LaneUse>& uses, double from, double period);

  std::size_t lanes() const { return heat_.size(); }
  int Heat(std::size_t lane) const { return heat_[lane]; }      // h_k
  int Robots(std::size_t lane) const { return robots_[lane]; }  // b_k
  double Weight(std::size_t lane) const { return weight_[lane]; }  // w_k = 1 + F_k
  // The weight of the lane arc `a` belongs to.
  double ArcWeight(const WarehouseMap& map, ArcId a) const;

 private:
  std::vector<int> heat_, robots_;
  std::vector<double> weight_;
};

// The route from -> to minimising the weighted drive time Σ w · length / v (step 5: Dijkstra
// over the heat-weighted lengths; v = `speed`, capped by an arc's own limit) plus, with
// turn_s_per_90 > 0, the turning time (Wang2019 eq. (3), t_c: seconds per 90 degrees of
// heading change between consecutive arcs, a U-turn twice; the seed's "improved Dijkstra" of
// §4.1 weighs both). `arrived_by` is the arc the robot reached `from` by (its heading), or -1
// (standing, heading unknown: the first arc turns nothing). With turning time the search runs
// over the arcs (the state is the arc a robot arrived by), exactly as MapCostGraph's
// arc-expanded graph. Route::cost is the unweighted drive time plus the turning time,
// Route::length the metres. Errors: kNotFound (unknown point), kUnreachable.
Result<Route> HeatRoute(const WarehouseMap& map, const PathHeat& heat, PointId from, PointId to, double speed,
                        double turn_s_per_90 = 0.0, ArcId arrived_by = -1);

// Step 5 as a route table (a weighted LazyRouteTable: one reverse search per destination, on
// demand): its routes are HeatRoute's for a robot standing (heading unknown), and Cost is their
// unweighted time, what a robot driving them takes. For the auction's bids under routing =
// heat (engine/dispatch/allocation_round.cpp). `options`: speed, turn_penalty_s, cache bound.
Result<std::unique_ptr<RouteTable>> HeatRouteTable(std::shared_ptr<const WarehouseMap> map, const PathHeat& heat,
                                                   const RouteTableOptions& options);

}  // namespace dispatch::engine
