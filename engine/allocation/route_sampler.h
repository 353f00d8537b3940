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
// RouteTable. Not thread-safe (the memo is mutable state). Construction allocates a memo
// entry per map point; Bind reuses it for another call (the auction keeps one sampler).
#pragma once

#include <limits>
#include <vector>

#include "engine/allocation/traffic_prediction.h"
#include "engine/fleet/plan.h"
#include "engine/map/warehouse_map.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine {

class RouteSampler {
 public:
  RouteSampler(const WarehouseMap& map, const RouteTable& routes, double speed, double step);

  // Starts over on `map` and `routes` (which may be new objects or changed tables): forgets
  // every memoised hop, keeping the memo's storage. O(hops memoised since the last Bind).
  void Bind(const WarehouseMap& map, const RouteTable& routes, double speed, double step);

  // Appends the samples of the drive from `from` (leaving at `depart`) to `to`, arrival point
  // excluded, and returns the arrival time; +infinity if `to` is unreachable (the samples
  // appended so far are then meaningless).
  double AppendLeg(PointId from, PointId to, double depart, std::vector<RouteSample>& out);

  // The same samples as AppendLeg, handed one at a time to visit(arc, xa, xb, f, t) instead
  // of stored: the sample lies on arc `arc` from xa to xb at xy = xa + f * (xb - xa) (compute
  // it with exactly this expression to get AppendLeg's bits) with 0 <= f < 1 (f is at most
  // rounding above 1), at time t. Returns what AppendLeg returns.
  template <typename Visit>
  double ForEachLegSample(PointId from, PointId to, double depart, Visit&& visit);

  // The arrival time of AppendLeg(from, to, 0, ...) up to rounding (the same hops' times,
  // summed from the far end), without the samples: memoised per point towards `to`, so the
  // legs of many robots to one pick cost about the points of their union. +infinity if `to`
  // is unreachable.
  double TimeToTarget(PointId from, PointId to);

  // Appends the samples of serving `task` for a robot arriving at its first pick at
  // `arrival`: every stop at its arrival, the legs between them, t_w at each stop. Returns the
  // departure time from the drop; +infinity if a leg is unreachable.
  double AppendTask(const PlanTask& task, double arrival, std::vector<RouteSample>& out);

 private:
  // The step out of a point towards memo_target_: the arc taken (-1 if unreachable), where it
  // ends, its length and its travel time ArcTime.
  struct Hop {
    ArcId arc = -2;  // -2: not yet known
    PointId to = kNoPoint;
    double length = 0.0;
    double dt = 0.0;
    double to_go = -1.0;  // TimeToTarget from this point; < 0: not yet known
  };
  // The hop the robot takes out of `p` towards memo_target_ (memoised).
  const Hop& NextHop(PointId p) {
    const Hop& hop = memo_[static_cast<std::size_t>(p)];
    return hop.arc != -2 ? hop : FindHop(p);
  }
  const Hop& FindHop(PointId p);
  double ArcTime(const Arc& arc) const;

  const WarehouseMap* map_ = nullptr;
  const RouteTable* routes_ = nullptr;
  double speed_ = 1.0;
  double step_ = 1.0;
  PointId memo_target_ = kNoPoint;
  std::vector<Hop> memo_;  // per point
  std::vector<PointId> touched_;
  std::vector<PointId> walk_;  // TimeToTarget's scratch

  void SetTarget(PointId to);
};

template <typename Visit>
double RouteSampler::ForEachLegSample(PointId from, PointId to, double depart, Visit&& visit) {
  SetTarget(to);
  double t = depart;
  double s0 = 0.0;      // distance driven at the start of the current arc
  double next_s = 0.0;  // distance of the next sample
  PointId p = from;
  std::size_t hops = 0;
  const std::size_t n_points = map_->point_count();
  const Point* points = map_->points().data();
  while (p != to) {
    const Hop& hop = NextHop(p);
    if (hop.arc < 0 || ++hops > n_points) return std::numeric_limits<double>::infinity();
    const Eigen::Vector2d& xa = points[p].position;
    const Eigen::Vector2d& xb = points[hop.to].position;
    const double dt = hop.dt;
    const double s1 = s0 + hop.length;
    // Samples strictly inside the leg; the arrival point belongs to the next stop.
    const double last = hop.to == to ? s1 - 1e-9 : s1;
    while (next_s < last) {
      const double f = (next_s - s0) / hop.length;
      visit(hop.arc, xa, xb, f, t + f * dt);
      next_s += step_;
    }
    t += dt;
    s0 = s1;
    p = hop.to;
  }
  return t;
}

}  // namespace dispatch::engine
