#include "engine/traffic/traffic_controller.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <queue>
#include <unordered_map>
#include <utility>

namespace dispatch::engine {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
enum class WaitKind { kNone, kPoint, kCorridor, kGrant };

struct RobotState {
  std::string id;
  PointId at = kNoPoint;
  PointId next = kNoPoint;
  std::vector<PointId> route;  // route[pos] == at
  std::vector<ArcId> arcs;     // arcs[k]: route[k] -> route[k + 1]
  std::size_t pos = 0;
  bool working = false, loaded = false, removed = false;
  int group = 0, group2 = 0;  // > 0: robots sharing a group (a formation) may come closer
  double envelope = 0.0;  // extra clearance (a formation's D_f), <= config.max_envelope
  double work_end = 0.0;
  bool idle = true;
  std::vector<int> corridors;  // held corridor reservations
  int guard = -1;              // intersection requested or granted
  bool granted = false;
  // Wait state (valid while wait != kNone).
  WaitKind wait = WaitKind::kNone;
  double wait_start = 0.0;
  double next_detour_try = 0.0;
  double next_break_try = 0.0;  // BreakCycle retries a robot that could not act after 1 s
  int waits_on = -1;
  PointId wait_point = kNoPoint;
  int wait_corridor = -1;
  int head_on_decided = -1;  // corridor whose head-on was decided in this wait
  std::string why;
};

struct CorridorState {
  int dir = 0;
  std::vector<int> holders;
  bool exclusive = false;  // a service point inside: one robot at a time
};

struct Detour {
  std::vector<PointId> points;
  double cost = kInf;
};

}  // namespace

struct TrafficController::Impl {
  std::shared_ptr<const WarehouseMap> map;
  TrafficControllerConfig config;
  LaneCorridors lanes;
  IntersectionGrants grants{0};
  // Points closer than point_clearance + 2 * max_envelope, with their distance.
  std::vector<std::vector<std::pair<PointId, double>>> near;
  std::vector<int> holder;                 // per point
  std::vector<CorridorState> cstate;
  std::vector<RobotState> robots;
  std::unordered_map<std::string, std::size_t> index;
  TrafficStats stats;
  // Dijkstra scratch.
  std::vector<double> dist;
  std::vector<ArcId> via;
  std::vector<std::uint32_t> seen;
  std::uint32_t stamp = 0;

  const WarehouseMap& M() const { return *map; }
  double ArcTime(ArcId a) const {
    const Arc& arc = M().arc(a);
    const double v = arc.max_speed > 0 ? std::min(config.speed, arc.max_speed) : config.speed;
    return arc.length / v;
  }
  int CorridorOf(ArcId a) const { return lanes.CorridorOfArc(M(), a); }
  int Priority(std::size_t r) const {
    const RobotState& x = robots[r];
    return x.working ? 2 : (x.loaded ? 1 : 0);
  }
  // True when robot a yields to robot b (a has lower priority).
  bool Lower(std::size_t a, std::size_t b) const {
    const int pa = Priority(a), pb = Priority(b);
    return pa != pb ? pa < pb : a > b;
  }

  int PointBlocker(PointId q, std::size_t r) const {
    const int h = holder[static_cast<std::size_t>(q)];
    if (h >= 0 && static_cast<std::size_t>(h) != r) return h;
    // Chu2024 eqs. (10)-(12): eps1 between singles, eps1 + D_f single-formation, eps1 + 2 D_f
    // between formations: each agent's envelope adds to the clearance.
    const RobotState& me = robots[r];
    auto mates = [&](const RobotState& o) {
      return (me.group > 0 && (o.group == me.group || o.group2 == me.group)) ||
             (me.group2 > 0 && (o.group == me.group2 || o.group2 == me.group2));
    };
    const double own = config.point_clearance + robots[r].envelope - 1e-9;
    for (const auto& [n, d] : near[static_cast<std::size_t>(q)]) {
      const int hn = holder[static_cast<std::size_t>(n)];
      if (hn < 0 || static_cast<std::size_t>(hn) == r) continue;
      const RobotState& other = robots[static_cast<std::size_t>(hn)];
      if (mates(other)) continue;
      if (d < own + other.envelope) return hn;
    }
    return -1;
  }
  // The robot holding corridor c the other way (-1: free for direction d).
  int CorridorBlocker(int c, int d, std::size_t r) const {
    const CorridorState& s = cstate[static_cast<std::size_t>(c)];
    if (s.dir == d && !s.exclusive) return -1;
    for (int h : s.holders) {
      if (static_cast<std::size_t>(h) != r) return h;
    }
    return -1;
  }
  void HoldCorridor(int c, int d, std::size_t r) {
    CorridorState& s = cstate[static_cast<std::size_t>(c)];
    s.dir = d;
    if (std::find(s.holders.begin(), s.holders.end(), static_cast<int>(r)) == s.holders.end()) {
      s.holders.push_back(static_cast<int>(r));
      robots[r].corridors.push_back(c);
    }
  }
  void DropCorridor(int c, std::size_t r) {
    CorridorState& s = cstate[static_cast<std::size_t>(c)];
    s.holders.erase(std::remove(s.holders.begin(), s.holders.end(), static_cast<int>(r)),
                    s.holders.end());
    if (s.holders.empty()) s.dir = 0;
    auto& mine = robots[r].corridors;
    mine.erase(std::remove(mine.begin(), mine.end(), c), mine.end());
  }
  // Keeps only the corridors the robot is inside of or drives on / looks ahead into.
  void ReconcileCorridors(std::size_t r) {
    RobotState& x = robots[r];
    const std::vector<int> held = x.corridors;
    for (int c : held) {
      bool keep = lanes.interior_of[static_cast<std::size_t>(x.at)] == c;
      for (std::size_t k = x.pos; k < x.arcs.size() && k < x.pos + 2 && !keep; ++k) {
        keep = CorridorOf(x.arcs[k]) == c;
      }
      if (!keep) DropCorridor(c, r);
    }
  }
  void ReleaseGuard(std::size_t r) {
    RobotState& x = robots[r];
    if (x.guard < 0) return;
    (void)grants.Release(static_cast<std::size_t>(x.guard), x.id);
    x.guard = -1;
    x.granted = false;
  }
  void ClearWait(RobotState& x) {
    x.wait = WaitKind::kNone;
    x.waits_on = -1;
    x.head_on_decided = -1;
  }
  TrafficDecision Wait(std::size_t r, WaitKind kind, int on, double t, std::string why) {
    RobotState& x = robots[r];
    if (x.wait == WaitKind::kNone) {
      x.wait_start = t;
      x.next_detour_try = 0.0;
    }
    x.wait = kind;
    x.waits_on = on;
    x.why = std::move(why);
    return TrafficDecision::kWait;
  }
  std::string Name(PointId p) const { return "'" + M().point(p).name + "'"; }

  double RouteCost(const RobotState& x) const {
    double c = 0;
    for (std::size_t k = x.pos; k < x.arcs.size(); ++k) c += ArcTime(x.arcs[k]);
    return c;
  }
  // Time until robot h has driven through corridor c (approach included) and one arc beyond.
  double ClearTime(std::size_t h, int c, double now) const {
    const RobotState& x = robots[h];
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

  // Cheapest route from -> to avoiding `ban_point`, corridor `ban_corridor` and intersection
  // `ban_guard` (each -1/kNoPoint for none). Empty points when there is none.
  // A* with the straight-line time as heuristic (admissible: paths are never shorter than
  // the straight distance and no robot is faster than `speed`); searches stop once every
  // open route costs more than `bound` seconds (no route returned then).
  Detour Route(PointId from, PointId to, PointId ban_point, int ban_corridor, int ban_guard,
               double bound = kInf) {
    Detour out;
    if (to == ban_point || from == to) {
      if (from == to) out = {{from}, 0.0};
      return out;
    }
    if (++stamp == 0) {
      std::fill(seen.begin(), seen.end(), 0);
      stamp = 1;
    }
    using Item = std::pair<double, PointId>;
    std::priority_queue<Item, std::vector<Item>, std::greater<>> heap;
    const Eigen::Vector2d goal = M().point(to).position;
    auto h = [&](PointId v) { return (M().point(v).position - goal).norm() / config.speed; };
    auto relax = [&](PointId v, double d, ArcId a) {
      const auto i = static_cast<std::size_t>(v);
      if (seen[i] == stamp && dist[i] <= d) return;
      seen[i] = stamp;
      dist[i] = d;
      via[i] = a;
      heap.push({d + h(v), v});
    };
    relax(from, 0.0, -1);
    bool found = false;
    while (!heap.empty()) {
      const auto [key, u] = heap.top();
      heap.pop();
      const double d = dist[static_cast<std::size_t>(u)];
      if (key > d + h(u) + 1e-12) continue;  // stale entry
      if (key > bound) break;
      if (u == to) {
        found = true;
        break;
      }
      for (ArcId a : M().out_arcs(u)) {
        const PointId v = M().arc(a).to;
        if (v == ban_point) continue;
        if (ban_corridor >= 0 && CorridorOf(a) == ban_corridor) continue;
        if (ban_guard >= 0 && M().IntersectionOf(v) == ban_guard && v != to) continue;
        relax(v, d + ArcTime(a), a);
      }
    }
    const auto ti = static_cast<std::size_t>(to);
    if (!found) return out;
    out.cost = dist[ti];
    for (PointId v = to; v != from; v = M().arc(via[static_cast<std::size_t>(v)]).from) {
      out.points.push_back(v);
    }
    out.points.push_back(from);
    std::reverse(out.points.begin(), out.points.end());
    return out;
  }

  Status Assign(std::size_t r, std::vector<PointId> points) {
    RobotState& x = robots[r];
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
    x.head_on_decided = -1;
    if (x.guard >= 0 && M().IntersectionOf(x.at) != x.guard) ReleaseGuard(r);
    ReconcileCorridors(r);
    return Ok{};
  }

  // A new route must not start against robots holding a corridor the other way (a robot
  // inside a corridor cannot turn back through its followers).
  bool StartAllowed(std::size_t r, const std::vector<PointId>& points) const {
    for (std::size_t k = 0; k + 1 < points.size() && k < 2; ++k) {
      auto a = M().FindArc(points[k], points[k + 1]);
      if (!a) return false;
      const int c = CorridorOf(*a);
      if (c >= 0 && CorridorBlocker(c, lanes.Direction(M(), *a), r) >= 0) return false;
    }
    return true;
  }
  // Re-plans robot r's route to its goal avoiding what it waits for; true when applied.
  bool TryDetour(std::size_t r, PointId ban_point, int ban_corridor, int ban_guard,
                 bool need_free_first_hop) {
    RobotState& x = robots[r];
    if (x.pos + 1 >= x.route.size()) return false;
    // Detours more than blocked_after longer than the current route are not worth taking
    // (and bounding keeps a failing search from sweeping the whole floor).
    const double bound = RouteCost(x) + config.blocked_after;
    Detour d = Route(x.at, x.route.back(), ban_point, ban_corridor, ban_guard, bound);
    if (d.points.size() < 2 || !StartAllowed(r, d.points)) return false;
    if (need_free_first_hop && PointBlocker(d.points[1], r) >= 0) return false;
    if (!Assign(r, std::move(d.points)).ok()) return false;
    ++stats.replans;
    ClearWait(x);
    return true;
  }
  // Steps robot r to a free neighbour (not `avoid`, not an intersection point) and re-plans
  // from there to its goal (if it has one), preferring routes that avoid `ban_point`.
  bool TryBackOff(std::size_t r, PointId avoid, PointId ban_point) {
    RobotState& x = robots[r];
    const PointId goal = x.pos + 1 < x.route.size() ? x.route.back() : kNoPoint;
    for (ArcId a : M().out_arcs(x.at)) {
      const PointId n = M().arc(a).to;
      if (n == avoid || n == ban_point || PointBlocker(n, r) >= 0) continue;
      if (M().IntersectionOf(n) >= 0) continue;
      const int c = CorridorOf(a);
      if (c >= 0 && CorridorBlocker(c, lanes.Direction(M(), a), r) >= 0) continue;
      std::vector<PointId> route{x.at};
      if (goal != kNoPoint) {
        const double bound = RouteCost(x) + config.blocked_after;
        Detour d = Route(n, goal, ban_point, -1, -1, bound);
        if (d.points.empty()) d = Route(n, goal, kNoPoint, -1, -1, bound);
        if (d.points.empty()) continue;
        route.insert(route.end(), d.points.begin(), d.points.end());
      } else {
        route.push_back(n);
      }
      if (!Assign(r, std::move(route)).ok()) continue;
      ++stats.replans;
      ClearWait(x);
      return true;
    }
    return false;
  }

  bool Siding(PointId p) const {
    return !IsServicePoint(M().point(p).kind) &&
           lanes.interior_of[static_cast<std::size_t>(p)] < 0 && M().IntersectionOf(p) < 0;
  }
  // Breadth-first search for the nearest free siding not on `keep_clear`; routes r there.
  bool StepAside(std::size_t r, const std::vector<PointId>& keep_clear) {
    RobotState& x = robots[r];
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

  TrafficDecision HeadOn(std::size_t r, int c, int oncoming, double t) {
    RobotState& x = robots[r];
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
      // kChooseFaster only needs detours faster than waiting: bound the search there.
      const double old_cost = RouteCost(x);
      const double bound = config.head_on == HeadOnPolicy::kChooseFaster
                               ? old_cost + rec.wait_estimate
                               : kInf;
      Detour d = Route(x.at, x.route.back(), kNoPoint, c, -1, bound);
      if (!d.points.empty() && !StartAllowed(r, d.points)) d = Detour{};
      rec.replan_extra = d.points.empty() ? kInf : d.cost - old_cost;
      const bool replan =
          !d.points.empty() && (config.head_on == HeadOnPolicy::kAlwaysReplan ||
                                (config.head_on == HeadOnPolicy::kChooseFaster &&
                                 rec.replan_extra < rec.wait_estimate));
      rec.replanned = replan;
      if (stats.head_on.size() < 1000) stats.head_on.push_back(rec);
      if (replan && Assign(r, std::move(d.points)).ok()) {
        ++stats.replans;
        ClearWait(x);
        return TrafficDecision::kReplanned;
      }
    }
    return Wait(r, WaitKind::kCorridor, oncoming, t,
                "head-on: corridor held by " + robots[static_cast<std::size_t>(oncoming)].id);
  }

  TrafficDecision Request(std::size_t r, double t) {
    RobotState& x = robots[r];
    if (x.removed || x.next != kNoPoint || x.pos + 1 >= x.route.size()) {
      x.why = "nothing to request";
      return TrafficDecision::kWait;
    }
    const PointId q = x.route[x.pos + 1];
    const TrafficDecision d = Check(r, q, t);
    if (d != TrafficDecision::kWait) return d;
    // Timeouts (Wang2019 §3.2 steps 3-4): re-plan, else blocked after blocked_after.
    const double waited = t - x.wait_start;
    const double limit = x.wait == WaitKind::kCorridor ? config.t_w1 : config.t_w2;
    if (waited >= limit && t >= x.next_detour_try) {
      x.next_detour_try = t + limit;
      const bool ok = x.wait == WaitKind::kCorridor
                          ? TryDetour(r, kNoPoint, x.wait_corridor, -1, false)
                          : x.wait == WaitKind::kGrant
                                ? TryDetour(r, kNoPoint, -1, M().IntersectionOf(q), false)
                                : TryDetour(r, q, -1, -1, false);
      if (ok) return TrafficDecision::kReplanned;
    }
    if (waited >= config.blocked_after) {
      char buf[96];
      std::snprintf(buf, sizeof buf, "blocked after waiting %.0f s at %s with no alternative: ",
                    waited, M().point(x.at).name.c_str());
      x.why = buf + x.why;
      return TrafficDecision::kBlocked;
    }
    return TrafficDecision::kWait;
  }

  TrafficDecision Check(std::size_t r, PointId q, double t) {
    RobotState& x = robots[r];
    const int blocker = PointBlocker(q, r);
    if (blocker >= 0) {
      x.wait_point = q;
      return Wait(r, WaitKind::kPoint, blocker, t,
                  "point " + Name(q) + " held by " + robots[static_cast<std::size_t>(blocker)].id);
    }
    for (std::size_t k = x.pos; k < x.arcs.size() && k < x.pos + 2; ++k) {
      const int c = CorridorOf(x.arcs[k]);
      if (c < 0) continue;
      const int on = CorridorBlocker(c, lanes.Direction(M(), x.arcs[k]), r);
      if (on < 0) continue;
      x.wait_corridor = c;
      return HeadOn(r, c, on, t);
    }
    const int g = config.intersection_grants ? M().IntersectionOf(q) : -1;
    if (g >= 0 && M().IntersectionOf(x.at) != g) {
      if (x.guard != g) {
        ReleaseGuard(r);
        std::size_t k = x.pos + 1;
        while (k + 1 < x.route.size() && M().IntersectionOf(x.route[k + 1]) == g) ++k;
        const PointId exit = k + 1 < x.route.size() ? x.route[k + 1] : kNoPoint;
        (void)grants.Request(static_cast<std::size_t>(g),
                             {x.id, {x.at, exit}, t, Priority(r)});
        x.guard = g;
        x.granted = false;
      }
      if (!grants.Granted(static_cast<std::size_t>(g), x.id)) {
        const auto holders = grants.Holders(static_cast<std::size_t>(g));
        int on = -1;
        if (!holders.empty()) on = static_cast<int>(index.at(holders.front()));
        return Wait(r, WaitKind::kGrant, on, t,
                    "waiting for a grant at " + M().intersections()[static_cast<std::size_t>(g)].name);
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

  void Arrived(std::size_t r) {
    RobotState& x = robots[r];
    if (x.next == kNoPoint) return;
    const PointId prev = x.at;
    x.at = x.next;
    x.next = kNoPoint;
    ++x.pos;
    if (holder[static_cast<std::size_t>(prev)] == static_cast<int>(r)) {
      holder[static_cast<std::size_t>(prev)] = -1;
    }
    ReconcileCorridors(r);
    if (x.guard >= 0 && x.granted && M().IntersectionOf(x.at) != x.guard) ReleaseGuard(r);
  }

  void Remove(std::size_t r) {
    RobotState& x = robots[r];
    for (PointId p : {x.at, x.next}) {
      if (p != kNoPoint && holder[static_cast<std::size_t>(p)] == static_cast<int>(r)) {
        holder[static_cast<std::size_t>(p)] = -1;
      }
    }
    const std::vector<int> held = x.corridors;
    for (int c : held) DropCorridor(c, r);
    ReleaseGuard(r);
    x.removed = true;
    x.route.clear();
    x.arcs.clear();
    x.pos = 0;
    x.next = kNoPoint;
    ClearWait(x);
  }

  bool BreakCycle(const std::vector<std::size_t>& members, double t) {
    std::vector<std::size_t> order = members;
    std::sort(order.begin(), order.end(),
              [&](std::size_t a, std::size_t b) { return Lower(a, b); });
    for (std::size_t v : order) {
      RobotState& x = robots[v];
      if (x.working || x.next != kNoPoint || t < x.next_break_try) continue;
      const PointId want = x.pos + 1 < x.route.size() ? x.route[x.pos + 1] : kNoPoint;
      const bool ok =
          x.wait == WaitKind::kCorridor ? TryDetour(v, kNoPoint, x.wait_corridor, -1, true)
          : x.wait == WaitKind::kGrant  ? TryDetour(v, kNoPoint, -1, M().IntersectionOf(want), true)
                                        : TryDetour(v, want, -1, -1, true);
      if (ok || TryBackOff(v, want, want)) return true;
      x.next_break_try = t + 1.0;
    }
    return false;
  }

  std::size_t ResolveDeadlocks(double t) {
    const std::size_t n = robots.size();
    std::vector<std::uint32_t> walk(n, 0);
    std::uint32_t walk_id = 0;
    std::size_t broken = 0;
    for (std::size_t s = 0; s < n; ++s) {
      if (walk[s] != 0 || robots[s].wait == WaitKind::kNone) continue;
      ++walk_id;
      std::vector<std::size_t> path;
      int v = static_cast<int>(s);
      while (v >= 0 && walk[static_cast<std::size_t>(v)] == 0) {
        walk[static_cast<std::size_t>(v)] = walk_id;
        path.push_back(static_cast<std::size_t>(v));
        const RobotState& x = robots[static_cast<std::size_t>(v)];
        v = x.wait != WaitKind::kNone ? x.waits_on : -1;
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
        const RobotState& w = robots[path[path.size() - 2]];
        RobotState& y = robots[h];
        if (y.idle && !y.removed && !y.working && y.next == kNoPoint &&
            y.pos + 1 >= y.route.size()) {
          std::vector<PointId> keep(w.route.begin() + static_cast<std::ptrdiff_t>(w.pos),
                                    w.route.end());
          if (StepAside(h, keep)) {
            ++stats.nudges;
          } else {
            const PointId want = w.pos + 1 < w.route.size() ? w.route[w.pos + 1] : kNoPoint;
            if (TryBackOff(h, w.at, want)) ++stats.nudges;
          }
        }
      }
    }
    return broken;
  }
};

Status TrafficControllerConfig::Validate() const {
  if (!std::isfinite(max_envelope) || max_envelope < 0) {
    return InvalidArgument("traffic controller: max_envelope must be finite and >= 0");
  }
  for (double v : {speed, t_w1, t_w2, blocked_after}) {
    if (!std::isfinite(v) || v <= 0) {
      return InvalidArgument("traffic controller: speed and waits must be finite and > 0");
    }
  }
  if (!std::isfinite(point_clearance) || point_clearance < 0) {
    return InvalidArgument("traffic controller: point_clearance must be finite and >= 0");
  }
  return Ok{};
}

Result<TrafficController> TrafficController::Create(std::shared_ptr<const WarehouseMap> map,
                                                    const TrafficControllerConfig& config) {
  if (!map) return InvalidArgument("traffic controller: no map");
  Status valid = config.Validate();
  if (!valid.ok()) return valid.error();
  auto impl = std::make_unique<Impl>();
  impl->map = std::move(map);
  impl->config = config;
  const WarehouseMap& m = *impl->map;
  impl->lanes = BuildLaneCorridors(m);
  impl->grants = IntersectionGrants(m.intersections().size());
  const std::size_t n = m.point_count();
  impl->holder.assign(n, -1);
  impl->cstate.assign(impl->lanes.corridors.size(), {});
  for (std::size_t c = 0; c < impl->lanes.corridors.size(); ++c) {
    const auto& pts = impl->lanes.corridors[c].points;
    for (std::size_t k = 1; k + 1 < pts.size(); ++k) {
      if (IsServicePoint(m.point(pts[k]).kind)) impl->cstate[c].exclusive = true;
    }
  }
  impl->dist.assign(n, kInf);
  impl->via.assign(n, -1);
  impl->seen.assign(n, 0);
  // Clearance neighbours by a uniform grid of cell size point_clearance.
  impl->near.assign(n, {});
  const double cell = config.point_clearance + 2.0 * config.max_envelope;
  if (cell > 0) {
    std::unordered_map<long long, std::vector<PointId>> grid;
    auto key = [&](long long ix, long long iy) { return ix * 1000003LL + iy; };
    auto cell_of = [&](const Eigen::Vector2d& p) {
      return std::pair<long long, long long>{static_cast<long long>(std::floor(p.x() / cell)),
                                             static_cast<long long>(std::floor(p.y() / cell))};
    };
    for (std::size_t p = 0; p < n; ++p) {
      auto [ix, iy] = cell_of(m.points()[p].position);
      grid[key(ix, iy)].push_back(static_cast<PointId>(p));
    }
    for (std::size_t p = 0; p < n; ++p) {
      const Eigen::Vector2d& xy = m.points()[p].position;
      auto [ix, iy] = cell_of(xy);
      for (long long dx = -1; dx <= 1; ++dx) {
        for (long long dy = -1; dy <= 1; ++dy) {
          auto it = grid.find(key(ix + dx, iy + dy));
          if (it == grid.end()) continue;
          for (PointId q : it->second) {
            const double d = (m.points()[static_cast<std::size_t>(q)].position - xy).norm();
            if (static_cast<std::size_t>(q) != p && d < cell - 1e-9) impl->near[p].push_back({q, d});
          }
        }
      }
    }
  }
  return TrafficController(std::move(impl));
}

TrafficController::TrafficController(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
TrafficController::TrafficController(TrafficController&&) noexcept = default;
TrafficController& TrafficController::operator=(TrafficController&&) noexcept = default;
TrafficController::~TrafficController() = default;

Result<std::size_t> TrafficController::AddRobot(const std::string& id, PointId at, int group) {
  Impl& s = *impl_;
  if (id.empty()) return InvalidArgument("traffic: empty robot id");
  if (at < 0 || static_cast<std::size_t>(at) >= s.M().point_count()) {
    return NotFound("traffic: robot " + id + " stands at an unknown point");
  }
  if (s.index.count(id)) return InvalidArgument("traffic: duplicate robot id " + id);
  const std::size_t r = s.robots.size();
  RobotState x;
  x.id = id;
  x.at = at;
  x.route = {at};
  x.group = std::max(0, group);
  s.robots.push_back(std::move(x));
  const int b = s.PointBlocker(at, r);
  if (b >= 0) {
    s.robots.pop_back();
    return InvalidArgument("traffic: robot " + id + " placed at " + s.Name(at) + " held by " +
                           s.robots[static_cast<std::size_t>(b)].id);
  }
  s.holder[static_cast<std::size_t>(at)] = static_cast<int>(r);
  s.index.emplace(id, r);
  return r;
}

std::size_t TrafficController::robot_count() const { return impl_->robots.size(); }
const std::string& TrafficController::robot_id(std::size_t r) const { return impl_->robots.at(r).id; }
Status TrafficController::SetRoute(std::size_t r, std::vector<PointId> points) {
  if (r >= impl_->robots.size()) return InvalidArgument("traffic: unknown robot index");
  return impl_->Assign(r, std::move(points));
}
std::vector<PointId> TrafficController::RemainingRoute(std::size_t r) const {
  const RobotState& x = impl_->robots.at(r);
  if (x.route.empty()) return {};
  return {x.route.begin() + static_cast<std::ptrdiff_t>(x.pos), x.route.end()};
}
bool TrafficController::HasRoute(std::size_t r) const {
  const RobotState& x = impl_->robots.at(r);
  return !x.removed && x.pos + 1 < x.route.size();
}
PointId TrafficController::At(std::size_t r) const { return impl_->robots.at(r).at; }
PointId TrafficController::Next(std::size_t r) const { return impl_->robots.at(r).next; }
void TrafficController::SetWorking(std::size_t r, bool working, double work_end) {
  impl_->robots.at(r).working = working;
  impl_->robots.at(r).work_end = work_end;
}
void TrafficController::SetLoaded(std::size_t r, bool loaded) { impl_->robots.at(r).loaded = loaded; }
void TrafficController::SetIdle(std::size_t r, bool idle) { impl_->robots.at(r).idle = idle; }
void TrafficController::SetGroup(std::size_t r, int group, int second) {
  impl_->robots.at(r).group = std::max(0, group);
  impl_->robots.at(r).group2 = std::max(0, second);
}
void TrafficController::SetEnvelope(std::size_t r, double extra) {
  impl_->robots.at(r).envelope = std::clamp(extra, 0.0, impl_->config.max_envelope);
}
TrafficDecision TrafficController::Request(std::size_t r, double t) {
  return impl_->Request(r, t);
}
void TrafficController::LeftPoint(std::size_t r) {
  Impl& s = *impl_;
  const RobotState& x = s.robots.at(r);
  if (x.next == kNoPoint) return;
  int& h = s.holder[static_cast<std::size_t>(x.at)];
  if (h == static_cast<int>(r)) h = -1;
}
void TrafficController::Arrived(std::size_t r, double /*t*/) { impl_->Arrived(r); }
void TrafficController::Remove(std::size_t r) { impl_->Remove(r); }
Status TrafficController::Place(std::size_t r, PointId at) {
  Impl& s = *impl_;
  if (r >= s.robots.size()) return InvalidArgument("traffic: unknown robot index");
  RobotState& x = s.robots[r];
  if (!x.removed) return Error{ErrorCode::kFailedPrecondition, "traffic: robot " + x.id + " is on the floor"};
  if (at < 0 || static_cast<std::size_t>(at) >= s.M().point_count()) {
    return NotFound("traffic: robot " + x.id + " placed at an unknown point");
  }
  const int b = s.PointBlocker(at, r);
  if (b >= 0) {
    return InvalidArgument("traffic: robot " + x.id + " placed at " + s.Name(at) + " held by " +
                           s.robots[static_cast<std::size_t>(b)].id);
  }
  x.removed = false;
  x.at = at;
  x.next = kNoPoint;
  x.route = {at};
  x.arcs.clear();
  x.pos = 0;
  x.working = x.loaded = false;
  x.idle = true;
  s.ClearWait(x);
  s.holder[static_cast<std::size_t>(at)] = static_cast<int>(r);
  return Ok{};
}
bool TrafficController::removed(std::size_t r) const { return impl_->robots.at(r).removed; }
int TrafficController::HolderOf(PointId p) const { return impl_->holder.at(static_cast<std::size_t>(p)); }
int TrafficController::WaitsOn(std::size_t r) const {
  const RobotState& x = impl_->robots.at(r);
  return x.wait == WaitKind::kNone ? -1 : x.waits_on;
}
void TrafficController::WaitOn(std::size_t r, int other, double t, const std::string& why) {
  RobotState& x = impl_->robots.at(r);
  if (other < 0 || static_cast<std::size_t>(other) >= impl_->robots.size() || static_cast<std::size_t>(other) == r) {
    if (x.wait != WaitKind::kNone) impl_->ClearWait(x);
    return;
  }
  (void)impl_->Wait(r, WaitKind::kPoint, other, t, why);
}
const std::string& TrafficController::why(std::size_t r) const { return impl_->robots.at(r).why; }
std::string TrafficController::Describe(std::size_t r) const {
  const Impl& s = *impl_;
  const RobotState& x = s.robots.at(r);
  std::string out = x.id + (x.removed ? " (off the floor)" : "") + " at " + s.Name(x.at);
  if (x.next != kNoPoint) out += " -> " + s.Name(x.next);
  out += " route";
  for (std::size_t k = x.pos; k < x.route.size() && k < x.pos + 6; ++k) out += " " + s.Name(x.route[k]);
  if (x.working) out += " working";
  if (x.wait != WaitKind::kNone) {
    out += " waiting on " + (x.waits_on >= 0 ? s.robots[static_cast<std::size_t>(x.waits_on)].id
                                              : std::string("-")) + " (" + x.why + ")";
  }
  return out;
}

bool TrafficController::StepAside(std::size_t r) { return impl_->StepAside(r, {}); }
bool TrafficController::StepAside(std::size_t r, const std::vector<PointId>& keep_clear) {
  return impl_->StepAside(r, keep_clear);
}

std::size_t TrafficController::ResolveDeadlocks(double t) { return impl_->ResolveDeadlocks(t); }
const TrafficStats& TrafficController::stats() const { return impl_->stats; }
const LaneCorridors& TrafficController::corridors() const { return impl_->lanes; }
const IntersectionGrants& TrafficController::grants() const { return impl_->grants; }

}  // namespace dispatch::engine
