// RouteSampler: timed samples along a robot's candidate route, the input of the traffic-flow
// term (Chu2024 §2.3, eq. (6): "take a route point every h along the path, at the time the
// robot is there").
//
// Convention (documented choice): every leg between two stops is sampled at distances
// 0, h, 2h, ... strictly below the leg's length from the leg's start, and every stop is sampled
// at its arrival time; so a stop with work time t_w is sampled on arrival and again (as the
// next leg's distance 0) on departure. Restarting at each stop makes a task's samples after
// its first pick the same for every robot up to a time shift, so the auction computes them
// once per order. Timing equals BuildPlan's: arc length / min(v, arc max speed) per arc, the
// position moving linearly between the arc's ends.
//
// Routes follow RouteTable::NextHop; next hops towards one target are memoised (the auction
// asks for many robots' legs to the same first pick), so a sampler must not outlive its
// RouteTable. Not thread-safe (the memo is mutable state); cheap to construct per order.
#pragma once

#include <vector>

#include "engine/allocation/traffic_prediction.h"
#include "engine/fleet/plan.h"
#include "engine/map/warehouse_map.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine {

class RouteSampler {
 public:
  RouteSampler(const WarehouseMap& map, const RouteTable& routes, double speed, double step);

  // Appends the samples of the drive from `from` (leaving at `depart`) to `to`, arrival point
  // excluded, and returns the arrival time; +infinity if `to` is unreachable (the samples
  // appended so far are then meaningless).
  double AppendLeg(PointId from, PointId to, double depart, std::vector<RouteSample>& out);

  // Appends the samples of serving `task` for a robot arriving at its first pick at
  // `arrival`: every stop at its arrival, the legs between them, t_w at each stop. Returns the
  // departure time from the drop; +infinity if a leg is unreachable.
  double AppendTask(const PlanTask& task, double arrival, std::vector<RouteSample>& out);

 private:
  // The arc the robot takes out of `p` towards memo_target_, or -1 if unreachable.
  ArcId NextArc(PointId p);
  double ArcTime(const Arc& arc) const;

  const WarehouseMap& map_;
  const RouteTable& routes_;
  double speed_;
  double step_;
  PointId memo_target_ = kNoPoint;
  std::vector<ArcId> memo_;  // per point: -2 unknown, -1 unreachable, else the arc
  std::vector<PointId> touched_;
};

}  // namespace dispatch::engine
