// TrafficController: head-on conflicts on single-lane corridors (Wang2019 §3.3). A robot that
// meets a corridor held the other way compares the expected wait with the extra time of a
// detour and takes the faster (HeadOn); with head_on_priority, a free corridor that a robot of
// higher priority is about to enter from the other end counts as held by it (case ①,
// PriorityOncoming). The shared state is in traffic_controller_impl.h.
#include <algorithm>
#include <string>
#include <vector>

#include "engine/traffic/traffic_controller_impl.h"

namespace dispatch::engine {

// Time until robot h has driven through corridor c (approach included) and one arc beyond.
double TrafficController::Impl::ClearTime(std::size_t h, int c, double now) const {
  const ControlledRobot& x = robots[h];
  double t = x.working ? std::max(0.0, x.work_end - now) : 0.0;
  bool entered = lanes.interior_of[static_cast<std::size_t>(x.at)] == c;
  for (std::size_t k = x.pos; k < x.arcs.size(); ++k) {
    const bool in = CorridorOf(x.arcs[k]) == c;
    t += ArcTime(x.arcs[k]);
    if (in) entered = true;
    if (!in && entered) break;
  }
  return t;
}

// Wang2019 §3.3 case ①: "if two robots driving at uniform speed on their original paths would
// meet head-on, the one of higher priority passes; the other adjusts (waits or re-plans,
// whichever is faster)". r is about to take free corridor c in direction d. A robot of higher
// priority (Lower) that is not waiting, whose route enters c from the other end before r
// would have driven through it, would meet r inside: it is returned as the oncoming robot
// (-1: none). Only robots standing on or driving to a point within as many arcs of c's far end
// as r's drive through c takes are looked at (a bounded search backwards from that end).
int TrafficController::Impl::PriorityOncoming(std::size_t r, int c, int d, double t) const {
  const ControlledRobot& x = robots[r];
  if (std::find(x.corridors.begin(), x.corridors.end(), c) != x.corridors.end()) return -1;  // it holds c
  double through = 0.0;  // r's time to the end of c
  bool in = false;
  std::size_t arcs_through = 0;
  for (std::size_t k = x.pos; k < x.arcs.size(); ++k) {
    const bool here = CorridorOf(x.arcs[k]) == c;
    if (!here && in) break;
    in = in || here;
    through += ArcTime(x.arcs[k]);
    ++arcs_through;
  }
  const LaneCorridor& lane = lanes.corridors[static_cast<std::size_t>(c)];
  const PointId far = d > 0 ? lane.points.back() : lane.points.front();
  // Backwards breadth-first from the far end, as many arcs deep as r's drive takes.
  std::vector<PointId> frontier{far}, next;
  std::vector<PointId> seen{far};
  int best = -1;
  for (std::size_t depth = 0; depth <= arcs_through && !frontier.empty(); ++depth) {
    for (PointId p : frontier) {
      const int h = holder[static_cast<std::size_t>(p)];
      if (h >= 0 && static_cast<std::size_t>(h) != r && (best < 0 || Lower(static_cast<std::size_t>(best), static_cast<std::size_t>(h)))) {
        const ControlledRobot& o = robots[static_cast<std::size_t>(h)];
        if (!o.removed && o.wait == WaitKind::kNone && !Mates(x, o) && Lower(r, static_cast<std::size_t>(h))) {
          // When does it enter c, and which way?
          double arrive = o.working ? std::max(0.0, o.work_end - t) : 0.0;
          for (std::size_t k = o.pos; k < o.arcs.size() && arrive < through; ++k) {
            if (CorridorOf(o.arcs[k]) == c) {
              if (lanes.Direction(M(), o.arcs[k]) != d) best = h;
              break;
            }
            arrive += ArcTime(o.arcs[k]);
          }
        }
      }
      for (ArcId a : M().in_arcs(p)) {
        const PointId q = M().arc(a).from;
        if (CorridorOf(a) == c || std::find(seen.begin(), seen.end(), q) != seen.end()) continue;
        seen.push_back(q);
        next.push_back(q);
      }
    }
    frontier.swap(next);
    next.clear();
  }
  return best;
}

TrafficDecision TrafficController::Impl::HeadOn(std::size_t r, int c, int oncoming, double t) {
  ControlledRobot& x = robots[r];
  if (x.head_on_decided != c) {
    x.head_on_decided = c;
    ++stats.head_on_conflicts;
    HeadOnRecord rec;
    rec.t = t;
    rec.robot = x.id;
    rec.oncoming = robots[static_cast<std::size_t>(oncoming)].id;
    for (int h : cstate[static_cast<std::size_t>(c)].holders) {
      if (static_cast<std::size_t>(h) == r) continue;
      rec.wait_estimate = std::max(rec.wait_estimate, ClearTime(static_cast<std::size_t>(h), c, t));
    }
    // Case ①: the oncoming robot has not reached the corridor yet.
    rec.wait_estimate = std::max(rec.wait_estimate, ClearTime(static_cast<std::size_t>(oncoming), c, t));
    // kChooseFaster only needs detours faster than waiting: bound the search there.
    const double old_cost = RouteCost(x);
    const double bound = config.head_on == HeadOnPolicy::kChooseFaster
                             ? old_cost + rec.wait_estimate
                             : kInf;
    const int keep_off = StickyCorridor(r);
    Detour d = Route(x.at, x.route.back(), StickyBan(r), c, -1, bound, keep_off != c ? keep_off : -1);
    // A route back to where the robot stands (out of the way and back, as a time-window plan
    // may go) has no detour: one of a single point would drop the loop, and the robot, its
    // plan's waypoints never released, would stand there for ever.
    if (d.points.size() < 2 || !StartAllowed(r, d.points)) d = Detour{};
    rec.replan_extra = d.points.empty() ? kInf : d.cost - old_cost;
    const bool replan =
        !d.points.empty() && (config.head_on == HeadOnPolicy::kAlwaysReplan ||
                              (config.head_on == HeadOnPolicy::kChooseFaster &&
                               rec.replan_extra < rec.wait_estimate));
    rec.replanned = replan;
    if (stats.head_on.size() < 1000) stats.head_on.push_back(rec);
    if (replan && Assign(r, std::move(d.points)).ok()) {
      Replanned(x);
      ClearWait(x);
      return TrafficDecision::kReplanned;
    }
  }
  return WaitFor(r, WaitKind::kCorridor, oncoming, t, WhyKey{1, oncoming},
                 [&] { return "head-on: corridor held by " + robots[static_cast<std::size_t>(oncoming)].id; });
}

}  // namespace dispatch::engine
