// TrafficGate: Wang2019 §3.2, the online stage of planned plans (PlanExecution::kOrder). The
// offline stage (the time-window planner) gives every robot a route with the times it passes
// each point; online, the order of the robots at each point is kept. A robot whose work at its
// waypoint is done and that would ask for its next point v first checks whether it is the
// robot that passes v next (step 1):
//  - no robot planned to pass v before it is on its way there: it asks (step 2);
//  - one is (v within its next few waypoints, in its current leg, and its way there does not
//    lead through the point the first one stands on, which it could not pass first): the first
//    one waits for it (step 3 ②), at most T_w1, then asks under the traffic controller's
//    rules (the seed re-plans its route; here the controller's detours and waits take over);
//  - one planned before it is not on its way to v: it loses its turn (step 3 ①).
// Never inside an intersection (its grant decides there). A point held by another robot (step
// 4) is the controller's: waits, T_w2 and detours. As with kClaim, robots still leave no
// earlier than their planned departures.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "engine/traffic/traffic_gate_impl.h"

namespace dispatch::engine {

namespace {

// How far ahead in a robot's plan its next pass of a point is looked for, in waypoints (and
// never beyond its next stop): "on its way there" is the seed's "within the next driving
// section through the point". Measured on the Chu2024 streams with 20% formations (seeds 1-3,
// time windows, before the intersection and next-stop rules): 1, 2, 4, 8 and 24 waypoints
// completed 577, 573, 591, 576 and 579 of 600.
constexpr long kOrderLookAhead = 4;

}  // namespace

bool GateImpl::AwaitsItsTurn(GateBot& b, double t, std::vector<GateEffect>& out) {
  if (config.execution != PlanExecution::kOrder || !b.team.empty() || b.idx < 0) return false;
  const auto r = static_cast<std::size_t>(b.ctl);
  const PointId at = ctl.At(r);
  // Inside an intersection its grant decides: it never stops there for its turn (a robot held
  // inside one, found in the Chu2024 burst, crossed with the next robot granted it).
  if (map->IntersectionOf(at) >= 0) return false;
  ctl.CopyRemainingRoute(r, order_route);
  if (order_route.size() < 2) return false;
  const PointId v = order_route[1];
  // Its own planned pass of v: the next waypoint there, right after the ones where it stands.
  const auto& w = b.plan.waypoints;
  const long n = static_cast<long>(w.size());
  long k = b.idx + 1;
  while (k < n && w[static_cast<std::size_t>(k)].point == at) ++k;
  if (k >= n || w[static_cast<std::size_t>(k)].point != v) return false;  // off its plan (a detour)
  const double mine = w[static_cast<std::size_t>(k)].eta;
  if (b.order_idx != b.idx || b.order_point != v) {
    b.order_idx = b.idx;
    b.order_point = v;
    b.order_since = t;
  }
  if (t - b.order_since >= config.t_w1) return false;  // waited T_w1: the controller's rules
  for (const GateBot* o : in_order) {
    if (o == &b || !o->team.empty() || !OnFloor(*o)) continue;
    const auto& ow = o->plan.waypoints;
    const long last = std::min(static_cast<long>(ow.size()) - 1, o->idx + kOrderLookAhead);
    for (long j = o->idx + 1; j <= last; ++j) {
      const Waypoint& p = ow[static_cast<std::size_t>(j)];
      if (p.point == at) break;  // its way to v leads through where b stands: b first
      if (p.point != v) {
        if (IsStop(p)) break;  // v is beyond its current leg
        continue;
      }
      if (p.eta < mine - 1e-9 || (std::abs(p.eta - mine) <= 1e-9 && o->id < b.id)) {
        char why[160];
        std::snprintf(why, sizeof why, "waiting for its turn at '%s': %s passes first (planned %.1f s before it)",
                      map->point(v).name.c_str(), o->id.c_str(), mine - p.eta);
        Hold(b, why, out);
        WakeAt(b.order_since + config.t_w1);
        return true;
      }
      break;
    }
  }
  return false;
}

}  // namespace dispatch::engine
