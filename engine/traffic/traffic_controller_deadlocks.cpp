// TrafficController's way out of waits: detours, backing off to a free neighbour, leaving a
// one-robot corridor, stepping aside to a siding, and breaking wait-for cycles
// (ResolveDeadlocks). The detour search (bounded A*) is in traffic_controller_search.cpp,
// requests in traffic_controller_requests.cpp, the public interface in traffic_controller.cpp,
// the shared state in traffic_controller_impl.h.
#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "engine/traffic/traffic_controller_impl.h"

namespace dispatch::engine {

bool TrafficController::Impl::StartAllowed(std::size_t r,
                                           const std::vector<PointId>& points) const {
  for (std::size_t k = 0; k + 1 < points.size() && k < 2; ++k) {
    auto a = M().FindArc(points[k], points[k + 1]);
    if (!a) return false;
    const int c = CorridorOf(*a);
    if (c >= 0 && CorridorBlocker(c, lanes.Direction(M(), *a), r) >= 0) return false;
  }
  return true;
}

PointId TrafficController::Impl::StickyBan(std::size_t r) {
  ControlledRobot& x = robots[r];
  if (x.avoiding == kNoPoint) return kNoPoint;
  if (x.avoiding != x.at && (x.route.empty() || x.avoiding != x.route.back()) &&
      PointBlocker(x.avoiding, r) == x.avoiding_holder) {
    return x.avoiding;
  }
  x.avoiding = kNoPoint;
  x.avoiding_holder = -1;
  return kNoPoint;
}

// See traffic_controller_impl.h.
int TrafficController::Impl::StickyCorridor(std::size_t r) {
  ControlledRobot& x = robots[r];
  const int c = x.avoiding_corridor;
  if (c < 0) return -1;
  auto inside = [&](PointId p) { return p != kNoPoint && lanes.interior_of[static_cast<std::size_t>(p)] == c; };
  const auto& holders = cstate[static_cast<std::size_t>(c)].holders;
  if (!inside(x.at) && (x.route.empty() || !inside(x.route.back())) &&
      std::find(holders.begin(), holders.end(), x.avoiding_corridor_holder) != holders.end()) {
    return c;
  }
  x.avoiding_corridor = -1;
  x.avoiding_corridor_holder = -1;
  return -1;
}

// Re-plans robot r's route to its goal avoiding what it waits for; true when applied.
bool TrafficController::Impl::TryDetour(std::size_t r, PointId ban_point, int ban_corridor,
                                        int ban_guard, bool need_free_first_hop) {
  ControlledRobot& x = robots[r];
  if (x.pos + 1 >= x.route.size()) return false;
  const int holder = ban_point != kNoPoint ? PointBlocker(ban_point, r) : -1;
  if (ban_point == kNoPoint) ban_point = StickyBan(r);
  // Detours more than blocked_after longer than the current route are not worth taking
  // (and bounding keeps a failing search from sweeping the whole floor).
  const double bound = RouteCost(x) + config.blocked_after;
  const int keep_off = StickyCorridor(r);
  Detour d = Route(x.at, x.route.back(), ban_point, ban_corridor, ban_guard, bound,
                   keep_off != ban_corridor ? keep_off : -1);
  if (d.points.size() < 2 || !StartAllowed(r, d.points)) return false;
  if (need_free_first_hop && PointBlocker(d.points[1], r) >= 0) return false;
  const int corridor_holder = ban_corridor >= 0 ? x.waits_on : -1;
  if (!Assign(r, std::move(d.points)).ok()) return false;
  if (holder >= 0) {
    x.avoiding = ban_point;
    x.avoiding_holder = holder;
  }
  if (corridor_holder >= 0) {
    x.avoiding_corridor = ban_corridor;
    x.avoiding_corridor_holder = corridor_holder;
  }
  Replanned(x);
  ClearWait(x);
  return true;
}

int TrafficController::Impl::NextCorridor(std::size_t w) const {
  const ControlledRobot& x = robots[w];
  if (x.wait == WaitKind::kCorridor && x.wait_corridor >= 0) return x.wait_corridor;
  return x.pos < x.arcs.size() ? CorridorOf(x.arcs[x.pos]) : -1;
}

// Steps robot r to a free neighbour (not `avoid`, not an intersection point) and re-plans
// from there to its goal (if it has one), preferring routes that avoid `ban_point`. Not to a
// point inside corridor `keep_out` when its route from there comes back through where it
// stood: it would hold that corridor against the other again at once. Found on a dense grid
// with the time-window planner: a robot inside a one-cell aisle backed off one cell and drove
// back, thousands of times, while the robot at the aisle's end waited on it until both were
// blocked (the one at the end had a way round).
bool TrafficController::Impl::TryBackOff(std::size_t r, PointId avoid, PointId ban_point, int keep_out) {
  ControlledRobot& x = robots[r];
  const PointId goal = x.pos + 1 < x.route.size() ? x.route.back() : kNoPoint;
  // A robot with nowhere to go, inside the one-robot corridor the other must enter: a step
  // within it still holds it, and the next back-off steps back (found on a dense grid: an idle
  // robot nudged between two points of such a corridor for 120 s, until the robot waiting for
  // it to clear was blocked). It leaves the corridor, or stays.
  if (goal == kNoPoint && keep_out >= 0 && lanes.interior_of[static_cast<std::size_t>(x.at)] == keep_out &&
      cstate[static_cast<std::size_t>(keep_out)].exclusive) {
    return LeaveCorridor(r, avoid, ban_point, keep_out);
  }
  for (ArcId a : M().out_arcs(x.at)) {
    const PointId n = M().arc(a).to;
    if (n == avoid || n == ban_point || PointBlocker(n, r) >= 0) continue;
    // Never into an intersection, but within the one it stands in (it holds its grant): a
    // robot, or a formation, stopped inside an intersection before an exit that stays held
    // backs off by the intersection's other exit.
    const int g = M().IntersectionOf(n);
    if (g >= 0 && g != M().IntersectionOf(x.at)) continue;
    const int c = CorridorOf(a);
    if (c >= 0 && CorridorBlocker(c, lanes.Direction(M(), a), r) >= 0) continue;
    std::vector<PointId> route{x.at};
    if (goal != kNoPoint) {
      const double bound = RouteCost(x) + config.blocked_after;
      Detour d = Route(n, goal, ban_point, -1, -1, bound, StickyCorridor(r));
      if (d.points.empty()) d = Route(n, goal, kNoPoint, -1, -1, bound);
      if (d.points.empty()) continue;
      // Inside the corridor the other must enter and back through where it stood: it would
      // hold that corridor the other way again at once.
      if (keep_out >= 0 && lanes.interior_of[static_cast<std::size_t>(n)] == keep_out &&
          std::find(d.points.begin(), d.points.end(), x.at) != d.points.end()) {
        continue;
      }
      route.insert(route.end(), d.points.begin(), d.points.end());
    } else {
      route.push_back(n);
    }
    if (!Assign(r, std::move(route)).ok()) continue;
    Replanned(x);
    ClearWait(x);
    return true;
  }
  return false;
}

bool TrafficController::Impl::LeaveCorridor(std::size_t r, PointId avoid, PointId ban_point, int corridor) {
  ControlledRobot& x = robots[r];
  if (++stamp == 0) {
    std::fill(seen.begin(), seen.end(), 0);
    stamp = 1;
  }
  std::vector<PointId> frontier{x.at};
  seen[static_cast<std::size_t>(x.at)] = stamp;
  for (std::size_t head = 0; head < frontier.size() && head < 64; ++head) {
    const PointId u = frontier[head];
    for (ArcId a : M().out_arcs(u)) {
      const PointId n = M().arc(a).to;
      const auto ni = static_cast<std::size_t>(n);
      if (seen[ni] == stamp || n == avoid || n == ban_point || PointBlocker(n, r) >= 0) continue;
      // As a back-off: never into an intersection but the one it stands in, nor against a
      // corridor's traffic.
      const int g = M().IntersectionOf(n);
      if (g >= 0 && g != M().IntersectionOf(x.at)) continue;
      const int c = CorridorOf(a);
      if (c >= 0 && CorridorBlocker(c, lanes.Direction(M(), a), r) >= 0) continue;
      seen[ni] = stamp;
      via[ni] = a;
      if (lanes.interior_of[ni] == corridor) {
        frontier.push_back(n);
        continue;
      }
      std::vector<PointId> route;
      for (PointId w = n; w != x.at; w = M().arc(via[static_cast<std::size_t>(w)]).from) route.push_back(w);
      route.push_back(x.at);
      std::reverse(route.begin(), route.end());
      if (!StartAllowed(r, route) || !Assign(r, std::move(route)).ok()) return false;
      Replanned(x);
      ClearWait(x);
      return true;
    }
  }
  return false;
}

bool TrafficController::Impl::Siding(PointId p) const {
  return !IsServicePoint(M().point(p).kind) &&
         lanes.interior_of[static_cast<std::size_t>(p)] < 0 && M().IntersectionOf(p) < 0;
}

// Breadth-first search for the nearest free siding not on `keep_clear`; routes r there.
bool TrafficController::Impl::StepAside(std::size_t r, const std::vector<PointId>& keep_clear) {
  ControlledRobot& x = robots[r];
  if (x.removed || x.working || x.next != kNoPoint || x.pos + 1 < x.route.size()) return false;
  // Kept clear: the given points, the service point it leaves (the next robot, or
  // formation, to serve there must be able to come), and every point within
  // point_clearance + max_envelope of those.
  std::vector<PointId> keep = keep_clear;
  if (IsServicePoint(M().point(x.at).kind)) keep.push_back(x.at);
  auto clear = [&](PointId p) {
    for (PointId k : keep) {
      if (p == k) return false;
      for (const auto& [n, d] : near[static_cast<std::size_t>(k)]) {
        if (n == p && d < config.point_clearance + config.max_envelope) return false;
      }
    }
    return true;
  };
  if (Siding(x.at) && clear(x.at)) return false;
  if (++stamp == 0) {
    std::fill(seen.begin(), seen.end(), 0);
    stamp = 1;
  }
  std::vector<PointId> frontier{x.at};
  seen[static_cast<std::size_t>(x.at)] = stamp;
  via[static_cast<std::size_t>(x.at)] = -1;
  for (std::size_t head = 0; head < frontier.size() && head < 40; ++head) {
    const PointId u = frontier[head];
    for (ArcId a : M().out_arcs(u)) {
      const PointId v = M().arc(a).to;
      const auto vi = static_cast<std::size_t>(v);
      if (seen[vi] == stamp || PointBlocker(v, r) >= 0) continue;
      seen[vi] = stamp;
      via[vi] = a;
      frontier.push_back(v);
      if (!Siding(v) || !clear(v)) continue;
      std::vector<PointId> route;
      for (PointId w = v; w != x.at; w = M().arc(via[static_cast<std::size_t>(w)]).from) {
        route.push_back(w);
      }
      route.push_back(x.at);
      std::reverse(route.begin(), route.end());
      if (!StartAllowed(r, route) || !Assign(r, std::move(route)).ok()) return false;
      return true;
    }
  }
  return false;
}

bool TrafficController::Impl::StandingIdle(std::size_t r) const {
  const ControlledRobot& y = robots[r];
  return y.idle && !y.removed && !y.working && y.next == kNoPoint && y.pos + 1 >= y.route.size();
}

// Found on the Wang2019 grid: a robot done at a corner drop stood boxed in by two idle robots
// that had stepped aside next to the drop and by the robot waiting to drop there; none could
// move, and the waiting robot was blocked.
bool TrafficController::Impl::MakeRoom(std::size_t h, const std::vector<PointId>& keep) {
  std::vector<PointId> clear = keep;
  clear.push_back(robots[h].at);
  for (ArcId a : M().out_arcs(robots[h].at)) {
    const int q = PointBlocker(M().arc(a).to, h);
    if (q < 0 || static_cast<std::size_t>(q) == h || !StandingIdle(static_cast<std::size_t>(q))) continue;
    clear.push_back(robots[static_cast<std::size_t>(q)].at);  // it leaves that point too
    if (StepAside(static_cast<std::size_t>(q), clear)) return true;
    clear.pop_back();
  }
  return false;
}

bool TrafficController::Impl::BreakCycle(const std::vector<std::size_t>& members, double t) {
  std::vector<std::size_t> order = members;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return Lower(a, b); });
  // A robot in a detour livelock acts last: re-planned by every cycle it meets it never
  // waits, and so is never found blocked (Request), while the others wait on it. Found on a
  // dense grid with the time-window planner: a robot drove round two cycles in turn, each
  // broken by its detour into the other, for 1,900 s while five robots waited on it (the run
  // ended at its limit with 25 orders open). Skipping it altogether had it blocked where the
  // re-plan would still have got it through.
  std::stable_partition(order.begin(), order.end(), [&](std::size_t v) { return !Livelocked(robots[v], t); });
  for (std::size_t v : order) {
    ControlledRobot& x = robots[v];
    if (x.working || x.next != kNoPoint || t < x.next_break_try) continue;
    for (std::size_t u : members) {  // Wang2019 §3.3 case ②: it gives way to the one waiting for it
      if (robots[u].waits_on == static_cast<int>(v) && MayGiveWay(v, u, t) && GiveWay(v, u, t)) return true;
    }
    const PointId want = x.pos + 1 < x.route.size() ? x.route[x.pos + 1] : kNoPoint;
    const bool ok =
        x.wait == WaitKind::kCorridor ? TryDetour(v, kNoPoint, x.wait_corridor, -1, true)
        : x.wait == WaitKind::kGrant  ? TryDetour(v, kNoPoint, -1, M().IntersectionOf(want), true)
                                      : TryDetour(v, want, -1, -1, true);
    int keep_out = -1;  // the corridor the robot waiting on it must enter
    for (std::size_t u : members) {
      if (robots[u].waits_on == static_cast<int>(v)) keep_out = NextCorridor(u);
    }
    if (ok || TryBackOff(v, want, want, keep_out)) return true;
    x.next_break_try = t + 1.0;
  }
  return false;
}

std::size_t TrafficController::Impl::ResolveDeadlocks(double t) {
  const std::size_t n = robots.size();
  std::vector<std::uint32_t>& walk = deadlock_walk;
  walk.assign(n, 0);
  std::uint32_t walk_id = 0;
  std::size_t broken = 0;
  for (std::size_t s = 0; s < n; ++s) {
    if (walk[s] != 0 || robots[s].wait == WaitKind::kNone) continue;
    ++walk_id;
    std::vector<std::size_t>& path = deadlock_path;
    path.clear();
    int v = static_cast<int>(s);
    while (v >= 0 && walk[static_cast<std::size_t>(v)] == 0) {
      walk[static_cast<std::size_t>(v)] = walk_id;
      path.push_back(static_cast<std::size_t>(v));
      const ControlledRobot& x = robots[static_cast<std::size_t>(v)];
      v = x.wait != WaitKind::kNone ? x.waits_on : -1;
    }
    // Wang2019 §3.3 case ②: along the chain, a waiting robot that waits for another than the
    // one waiting for it (those pairs are cycles, below) gives way to it when it may.
    bool gave_way = false;
    for (std::size_t i = 0; config.head_on_give_way && i + 1 < path.size() && !gave_way; ++i) {
      const std::size_t w = path[i], h = path[i + 1];
      if (robots[h].waits_on == static_cast<int>(w) || t < robots[h].next_break_try || !MayGiveWay(h, w, t)) continue;
      gave_way = GiveWay(h, w, t);
      if (!gave_way) robots[h].next_break_try = t + 1.0;
    }
    if (gave_way) {
      ++broken;
      continue;
    }
    if (v >= 0 && walk[static_cast<std::size_t>(v)] == walk_id) {
      auto it = std::find(path.begin(), path.end(), static_cast<std::size_t>(v));
      std::vector<std::size_t> cycle(it, path.end());
      if (BreakCycle(cycle, t)) {
        ++broken;
        ++stats.deadlocks_resolved;
      }
    } else if (v < 0 && path.size() >= 2) {
      // The chain ends at a robot that does not wait: nudge it aside if it is idle.
      const std::size_t h = path.back();
      const ControlledRobot& w = robots[path[path.size() - 2]];
      if (StandingIdle(h)) {
        std::vector<PointId> keep(w.route.begin() + static_cast<std::ptrdiff_t>(w.pos),
                                  w.route.end());
        if (StepAside(h, keep)) {
          ++stats.nudges;
        } else {
          const PointId want = w.pos + 1 < w.route.size() ? w.route[w.pos + 1] : kNoPoint;
          if (TryBackOff(h, w.at, want, NextCorridor(path[path.size() - 2])) || MakeRoom(h, keep)) ++stats.nudges;
        }
      }
    }
  }
  return broken;
}

}  // namespace dispatch::engine
