// TrafficController's requests (what Request() decides): point reservations and clearance
// (PointBlocker), single-lane corridors (head-on conflicts: traffic_controller_head_on.cpp),
// intersection grants, waits and
// their timeouts, route assignment, and arriving at / leaving the floor. Detours, back-off,
// sidings and deadlocks are in traffic_controller_deadlocks.cpp, the public interface in
// traffic_controller.cpp, the shared state in traffic_controller_impl.h.
#include <algorithm>
#include <cstdio>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "engine/traffic/traffic_controller_impl.h"

namespace dispatch::engine {

int TrafficController::Impl::PointBlocker(PointId q, std::size_t r, double envelope) const {
  const int h = holder[static_cast<std::size_t>(q)];
  if (h >= 0 && static_cast<std::size_t>(h) != r) return h;
  // Chu2024 eqs. (10)-(12): eps1 between singles, eps1 + D_f single-formation, eps1 + 2 D_f
  // between formations: each agent's envelope adds to the clearance.
  const ControlledRobot& me = robots[r];
  auto mates = [&](const ControlledRobot& o) { return Mates(me, o); };
  const double own = config.point_clearance + std::clamp(envelope, 0.0, config.max_envelope) - 1e-9;
  for (const auto& [n, d] : near[static_cast<std::size_t>(q)]) {
    const int hn = holder[static_cast<std::size_t>(n)];
    if (hn < 0 || static_cast<std::size_t>(hn) == r) continue;
    const ControlledRobot& other = robots[static_cast<std::size_t>(hn)];
    if (mates(other)) continue;
    if (d < own + other.envelope) return hn;
  }
  for (const auto& [s, xy] : standing) {  // off the floor, still standing there
    if (s == r) continue;
    const ControlledRobot& other = robots[s];
    if (mates(other)) continue;
    if ((point_xy[static_cast<std::size_t>(q)] - xy).norm() < own + other.envelope) return static_cast<int>(s);
  }
  return -1;
}

int TrafficController::Impl::RegionBlocker(PointId q, std::size_t r) const {
  const int f = region_of[static_cast<std::size_t>(q)];
  const ControlledRobot& x = robots[r];
  if (f < 0 || (x.at != kNoPoint && region_of[static_cast<std::size_t>(x.at)] == f)) return -1;
  auto in = [&](PointId p) { return p != kNoPoint && region_of[static_cast<std::size_t>(p)] == f; };
  for (std::size_t h = 0; h < robots.size(); ++h) {
    const ControlledRobot& o = robots[h];
    if (h == r || o.removed || Mates(x, o)) continue;
    if (in(o.at) || in(o.next)) return static_cast<int>(h);
  }
  return -1;
}

// The robot holding corridor c the other way (-1: free for direction d).
int TrafficController::Impl::CorridorBlocker(int c, int d, std::size_t r) const {
  const CorridorState& s = cstate[static_cast<std::size_t>(c)];
  if (s.dir == d && !s.exclusive) return -1;
  // Inside a one-robot corridor already, r may drive on away from holders behind it (found on
  // a dense grid: an idle robot inside such a corridor could not step aside for a formation,
  // the corridor held by one that waited for that formation behind it).
  const auto& points = lanes.corridors[static_cast<std::size_t>(c)].points;
  auto index = [&](PointId p) {
    const auto it = std::find(points.begin(), points.end(), p);
    return it == points.end() ? -1L : static_cast<long>(it - points.begin());
  };
  const PointId at = robots[r].at;
  const long mine = s.exclusive && at >= 0 && lanes.interior_of[static_cast<std::size_t>(at)] == c ? index(at) : -1;
  for (int h : s.holders) {
    const ControlledRobot& o = robots[static_cast<std::size_t>(h)];
    // A teammate (a member leaving its team's agent) is exempt, as in PointBlocker.
    if (static_cast<std::size_t>(h) == r || Mates(robots[r], o)) continue;
    if (mine >= 0 && o.next == kNoPoint) {
      const long k = index(o.at);
      if (k >= 0 && (k - mine) * d < 0) continue;
    }
    return h;
  }
  return -1;
}

void TrafficController::Impl::HoldCorridor(int c, int d, std::size_t r) {
  CorridorState& s = cstate[static_cast<std::size_t>(c)];
  s.dir = d;
  if (std::find(s.holders.begin(), s.holders.end(), static_cast<int>(r)) == s.holders.end()) {
    s.holders.push_back(static_cast<int>(r));
    robots[r].corridors.push_back(c);
  }
}

void TrafficController::Impl::DropCorridor(int c, std::size_t r) {
  CorridorState& s = cstate[static_cast<std::size_t>(c)];
  s.holders.erase(std::remove(s.holders.begin(), s.holders.end(), static_cast<int>(r)),
                  s.holders.end());
  if (s.holders.empty()) s.dir = 0;
  auto& mine = robots[r].corridors;
  mine.erase(std::remove(mine.begin(), mine.end(), c), mine.end());
}

// Keeps only the corridors the robot is inside of or drives on / looks ahead into.
void TrafficController::Impl::ReconcileCorridors(std::size_t r) {
  ControlledRobot& x = robots[r];
  if (x.corridors.empty()) return;
  std::vector<int>& held = corridor_scratch;  // DropCorridor edits x.corridors
  held = x.corridors;
  for (int c : held) {
    bool keep = lanes.interior_of[static_cast<std::size_t>(x.at)] == c;
    for (std::size_t k = x.pos; k < x.arcs.size() && k < x.pos + 2 && !keep; ++k) {
      keep = CorridorOf(x.arcs[k]) == c;
    }
    if (!keep) DropCorridor(c, r);
  }
}

void TrafficController::Impl::ReleaseGuard(std::size_t r) {
  ControlledRobot& x = robots[r];
  if (x.guard < 0) return;
  (void)grants.Release(static_cast<std::size_t>(x.guard), x.id);
  x.guard = -1;
  x.granted = false;
}

void TrafficController::Impl::OccupyGuard(std::size_t r, int g) {
  ControlledRobot& x = robots[r];
  if (!config.intersection_grants) g = -1;
  if (g >= 0 && x.guard == g && x.granted) return;
  ReleaseGuard(r);
  if (g < 0) return;
  (void)grants.Occupy(static_cast<std::size_t>(g), x.id);
  x.guard = g;
  x.granted = true;
}

void TrafficController::Impl::ClearWait(ControlledRobot& x) {
  x.wait = WaitKind::kNone;
  x.waits_on = -1;
  x.head_on_decided = -1;
}

TrafficDecision TrafficController::Impl::Wait(std::size_t r, WaitKind kind, int on, double t,
                                              std::string why) {
  return Wait(r, kind, on, t, std::move(why), WhyKey{});
}

TrafficDecision TrafficController::Impl::Wait(std::size_t r, WaitKind kind, int on, double t, std::string why,
                                              const WhyKey& key) {
  ControlledRobot& x = robots[r];
  x.why_key = key;
  if (x.wait == WaitKind::kNone) {
    x.wait_start = t;
    x.next_detour_try = 0.0;
  }
  x.wait = kind;
  x.waits_on = on;
  x.why = std::move(why);
  return TrafficDecision::kWait;
}

double TrafficController::Impl::RouteCost(const ControlledRobot& x) const {
  double c = 0;
  for (std::size_t k = x.pos; k < x.arcs.size(); ++k) c += ArcTime(x.arcs[k]);
  return c;
}

Status TrafficController::Impl::Assign(std::size_t r, std::vector<PointId> points) {
  ControlledRobot& x = robots[r];
  if (x.removed) return Error{ErrorCode::kFailedPrecondition, "traffic: robot " + x.id + " is off the floor"};
  if (x.next != kNoPoint) return Error{ErrorCode::kFailedPrecondition, "traffic: robot " + x.id + " is driving"};
  if (points.empty() || points.front() != x.at) {
    return InvalidArgument("traffic: route of " + x.id + " must start where it stands");
  }
  std::vector<ArcId> arcs;
  for (std::size_t k = 0; k + 1 < points.size(); ++k) {
    if (points[k] < 0 || static_cast<std::size_t>(points[k + 1]) >= M().point_count()) {
      return InvalidArgument("traffic: route of " + x.id + " names an unknown point");
    }
    auto a = M().FindArc(points[k], points[k + 1]);
    if (!a) {
      return InvalidArgument("traffic: route of " + x.id + " has no arc " + Name(points[k]) +
                             " -> " + Name(points[k + 1]));
    }
    arcs.push_back(*a);
  }
  x.route = std::move(points);
  x.arcs = std::move(arcs);
  x.pos = 0;
  Touch(x);
  x.head_on_decided = -1;
  if (x.guard >= 0 && M().IntersectionOf(x.at) != x.guard) ReleaseGuard(r);
  ReconcileCorridors(r);
  return Ok{};
}

void TrafficController::Impl::NoteProgress(ControlledRobot& x, double t) {
  if (!bound_routes) return;
  const PointId goal = x.route.back();
  if (goal == x.progress_goal && x.at == x.progress_at) return;
  x.progress_at = x.at;
  const double cost = bound_routes->Cost(x.at, goal);
  if (goal == x.progress_goal && !(cost < x.progress_best - 1e-9)) return;
  x.progress_goal = goal;  // a new goal, or closer to it
  x.progress_best = cost;
  x.progress_since = t;
  x.replanned_at.clear();
  x.replans_again = 0;
}

TrafficDecision TrafficController::Impl::Request(std::size_t r, double t) {
  ControlledRobot& x = robots[r];
  if (x.removed || x.next != kNoPoint || x.pos + 1 >= x.route.size()) {
    x.why = "nothing to request";
    x.why_key = {};
    return TrafficDecision::kWait;
  }
  const PointId q = x.route[x.pos + 1];
  NoteProgress(x, t);
  const TrafficDecision d = Check(r, q, t);
  if (d != TrafficDecision::kWait) return d;
  // A detour livelock: re-planned back and forth (twice again at points it had re-planned at)
  // and no closer to its goal for blocked_after. Its alternatives are taken by robots that
  // wait for it: it has none left, like a robot blocked after waiting (Wang2019 §3.2 step 4).
  if (Livelocked(x, t)) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "blocked after %.0f s at %s re-planning back and forth, no closer to %s: ",
                  t - x.progress_since, M().point(x.at).name.c_str(), M().point(x.progress_goal).name.c_str());
    x.why = buf + x.why;
    x.why_key = {};
    return TrafficDecision::kBlocked;
  }
  // Timeouts (Wang2019 §3.2 steps 3-4): re-plan, else blocked after blocked_after.
  const double waited = t - x.wait_start;
  const double limit = x.wait == WaitKind::kCorridor ? config.t_w1 : config.t_w2;
  if (waited >= limit && t >= x.next_detour_try) {
    x.next_detour_try = t + limit;
    const bool ok = x.wait == WaitKind::kCorridor
                        ? TryDetour(r, kNoPoint, x.wait_corridor, -1, false)
                        : x.wait == WaitKind::kGrant
                              ? TryDetour(r, kNoPoint, -1, M().IntersectionOf(q), false)
                              : TryDetour(r, x.wait_point != kNoPoint ? x.wait_point : q, -1, -1, false);
    if (ok) return TrafficDecision::kReplanned;
  }
  if (waited >= config.blocked_after) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "blocked after waiting %.0f s at %s with no alternative: ",
                  waited, M().point(x.at).name.c_str());
    x.why = buf + x.why;
    x.why_key = {};
    return TrafficDecision::kBlocked;
  }
  return TrafficDecision::kWait;
}

int TrafficController::Impl::WorkAhead(std::size_t r, std::size_t from, bool box_exit, double t) const {
  const ControlledRobot& x = robots[r];
  for (std::size_t k = from; k < x.route.size(); ++k) {
    const PointId p = x.route[k];
    if (const int w = PointBlocker(p, r); w >= 0 && k > x.pos + 1) {
      const ControlledRobot& o = robots[static_cast<std::size_t>(w)];
      const bool long_work = o.work_end > t + config.blocked_after;
      if (o.working && o.next == kNoPoint && !Mates(x, o) && ((box_exit && k == from) || long_work)) return w;
    }
    if (k + 1 >= x.route.size() || TurnOff(p, x.route[k + 1])) break;
    if (k >= 1 && x.route[k + 1] == x.route[k - 1]) break;  // it turns back here (a back-off)
  }
  return -1;
}

bool TrafficController::Impl::TurnOff(PointId p, PointId next) const {
  for (ArcId a : M().out_arcs(p)) {
    const PointId q = M().arc(a).to;
    if (q == next) continue;
    for (ArcId b : M().out_arcs(q)) {
      if (M().arc(b).to != p) return true;  // not a dead end (a dock) that only leads back
    }
  }
  return false;
}

TrafficDecision TrafficController::Impl::Check(std::size_t r, PointId q, double t) {
  ControlledRobot& x = robots[r];
  if (const int w = GivingWayTo(r, t); w >= 0) {  // Wang2019 §3.3 case ②
    x.wait_point = q;
    return WaitFor(r, WaitKind::kPoint, w, t, WhyKey{5, q, w},
                   [&] { return "giving way to " + robots[static_cast<std::size_t>(w)].id + " (head-on)"; });
  }
  const int blocker = PointBlocker(q, r);
  if (blocker >= 0) {
    x.wait_point = q;
    return WaitFor(r, WaitKind::kPoint, blocker, t, WhyKey{2, q, blocker},
                   [&] { return "point " + Name(q) + " held by " + robots[static_cast<std::size_t>(blocker)].id; });
  }
  if (const int holder_in = RegionBlocker(q, r); holder_in >= 0) {
    x.wait_point = q;
    const int f = region_of[static_cast<std::size_t>(q)];
    return WaitFor(r, WaitKind::kPoint, holder_in, t, WhyKey{6, f, holder_in}, [&] {
      return "free-space region '" + M().free_spaces()[static_cast<std::size_t>(f)].name + "' held by " +
             robots[static_cast<std::size_t>(holder_in)].id;
    });
  }
  for (std::size_t k = x.pos; k < x.arcs.size() && k < x.pos + 2; ++k) {
    const int c = CorridorOf(x.arcs[k]);
    if (c < 0) continue;
    const int d = lanes.Direction(M(), x.arcs[k]);
    int on = CorridorBlocker(c, d, r);
    if (on < 0 && config.head_on_priority) on = PriorityOncoming(r, c, d, t);
    if (on < 0) continue;
    x.wait_corridor = c;
    return HeadOn(r, c, on, t);
  }
  const int g = config.intersection_grants ? M().IntersectionOf(q) : -1;
  const bool entering = g >= 0 && M().IntersectionOf(x.at) != g;
  std::size_t k = x.pos + 1;  // entering: the last route point inside the intersection
  while (entering && k + 1 < x.route.size() && M().IntersectionOf(x.route[k + 1]) == g) ++k;
  const PointId exit = entering && k + 1 < x.route.size() ? x.route[k + 1] : kNoPoint;
  // Do not block the box, nor an aisle: it does not drive into an intersection whose exit is
  // taken by an agent standing at work, nor onto points with no turn-off before an agent that
  // works longer than anyone may wait (a formation assembling). It waits where it can still
  // be passed: inside, it would hold the grant or the aisle for as long as the work lasts, and
  // the robots the work waits for may need them.
  if (const int w = WorkAhead(r, entering ? k + 1 : x.pos + 1, entering, t); w >= 0) {
    // A queued request is withdrawn (it waits outside); a grant it stands inside on is kept
    // until it has left: found by the core's safety check (200 random orders, 20% formations,
    // seed 1, 942.8 s), a robot waiting inside an intersection for an aisle let its grant go,
    // and a crossing movement was granted around it.
    if (x.guard < 0 || M().IntersectionOf(x.at) != x.guard) ReleaseGuard(r);
    const ControlledRobot& o = robots[static_cast<std::size_t>(w)];
    x.wait_point = o.at;
    const bool at_exit = entering && o.at == exit;
    return WaitFor(r, WaitKind::kPoint, w, t, WhyKey{3, w, o.at, at_exit ? g : -1}, [&] {
      return (at_exit ? "exit of " + M().intersections()[static_cast<std::size_t>(g)].name + ": "
                      : std::string("no turn-off before ")) +
             Name(o.at) + " held by " + o.id + " at work";
    });
  }
  if (entering) {
    if (x.guard != g) {
      ReleaseGuard(r);
      (void)grants.Request(static_cast<std::size_t>(g),
                           {x.id, {x.at, exit}, t, Priority(r)});
      x.guard = g;
      x.granted = false;
    }
    if (!grants.Granted(static_cast<std::size_t>(g), x.id)) {
      const auto holders = grants.Holders(static_cast<std::size_t>(g));
      int on = -1;
      if (!holders.empty()) on = static_cast<int>(index.at(holders.front()));
      return WaitFor(r, WaitKind::kGrant, on, t, WhyKey{4, g},
                     [&] { return "waiting for a grant at " + M().intersections()[static_cast<std::size_t>(g)].name; });
    }
    if (!x.granted) {
      x.granted = true;
      ++stats.grants;
    }
  }
  // Take the reservations.
  holder[static_cast<std::size_t>(q)] = static_cast<int>(r);
  x.next = q;
  for (std::size_t k = x.pos; k < x.arcs.size() && k < x.pos + 2; ++k) {
    const int c = CorridorOf(x.arcs[k]);
    if (c >= 0) HoldCorridor(c, lanes.Direction(M(), x.arcs[k]), r);
  }
  ClearWait(x);
  return TrafficDecision::kGo;
}

void TrafficController::Impl::Arrived(std::size_t r) {
  ControlledRobot& x = robots[r];
  if (x.next == kNoPoint) return;
  const PointId prev = x.at;
  x.at = x.next;
  x.next = kNoPoint;
  ++x.pos;
  Touch(x);
  if (holder[static_cast<std::size_t>(prev)] == static_cast<int>(r)) {
    holder[static_cast<std::size_t>(prev)] = -1;
  }
  ReconcileCorridors(r);
  if (x.guard >= 0 && x.granted && M().IntersectionOf(x.at) != x.guard) ReleaseGuard(r);
}

void TrafficController::Impl::Remove(std::size_t r) {
  ControlledRobot& x = robots[r];
  for (PointId p : {x.at, x.next}) {
    if (p != kNoPoint && holder[static_cast<std::size_t>(p)] == static_cast<int>(r)) {
      holder[static_cast<std::size_t>(p)] = -1;
    }
  }
  const std::vector<int> held = x.corridors;
  for (int c : held) DropCorridor(c, r);
  ReleaseGuard(r);
  x.removed = true;
  x.give_way_to = -1;
  ForgetProgress(x);
  x.route.clear();
  x.arcs.clear();
  x.pos = 0;
  Touch(x);
  x.next = kNoPoint;
  ClearWait(x);
}

}  // namespace dispatch::engine
