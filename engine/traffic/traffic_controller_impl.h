// TrafficController's internal state, shared by traffic_controller.cpp (creation and the
// public interface), traffic_controller_requests.cpp (points, corridors, grants, waits) and
// traffic_controller_deadlocks.cpp (detours, back-off, sidings, deadlocks). Internal to the
// controller; see traffic_controller.h for the model. Include it only from those files.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "engine/common/numbers.h"
#include "engine/traffic/traffic_controller.h"

namespace dispatch::engine {
namespace traffic_detail {

enum class WaitKind { kNone, kPoint, kCorridor, kGrant };

// The facts a wait's reason is formatted from (site, and up to three ids); site 0: none.
struct WhyKey {
  int site = 0, a = -1, b = -1, c = -1;
  bool operator==(const WhyKey&) const = default;
};

struct ControlledRobot {
  std::string id;
  PointId at = kNoPoint;
  PointId next = kNoPoint;
  std::vector<PointId> route;  // route[pos] == at
  std::vector<ArcId> arcs;     // arcs[k]: route[k] -> route[k + 1]
  std::size_t pos = 0;
  // Moves on whenever route or pos changes (Impl::Touch): never the same for two values, of
  // this robot or any other (RouteEpoch).
  std::uint64_t route_epoch = 0;
  bool working = false, loaded = false, removed = false;
  int group = 0, group2 = 0, group3 = 0;  // > 0: robots sharing a group (a formation) may come closer
  double envelope = 0.0;  // extra clearance (a formation's D_f), <= config.max_envelope
  double work_end = 0.0;
  double rank = std::numeric_limits<double>::infinity();  // its task's release time (SetRank)
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
  // The point its last detour went round, and the robot that held it then (-1: none): later
  // detours keep going round it while that robot holds it (StickyBan).
  PointId avoiding = kNoPoint;
  int avoiding_holder = -1;
  // The same for the corridor its last detour went round, and the robot it waited on there
  // (StickyCorridor).
  int avoiding_corridor = -1;
  int avoiding_corridor_holder = -1;
  std::string why;
  // Giving way (Wang2019 §3.3 case ②, GiveWay): to this robot (-1: none), until then at most.
  int give_way_to = -1;
  double give_way_until = 0.0;
  // The robot it last gave way to and when: it gives way to the same one again only after
  // blocked_after (a second meeting soon after is left to the cycle breaking, else two robots
  // meet, part and meet again for ever).
  int gave_way_to = -1;
  double gave_way_at = 0.0;
  // What `why` was formatted from when a keyed wait wrote it (WaitFor): the same key again
  // leaves the text as it is (a waiting robot asks every step); any other write clears it.
  WhyKey why_key;
  // Progress towards the route's goal (NoteProgress): the least table cost to the goal from a
  // point it asked to leave, since when it is that low, the points it re-planned at since and
  // how often it re-planned again at one of them. A robot that re-plans back and forth
  // without getting closer (a detour livelock: each detour restarts its wait clock) is blocked
  // like one that waits (Request).
  PointId progress_goal = kNoPoint;
  PointId progress_at = kNoPoint;  // the point last measured from (a waiting robot asks again)
  double progress_best = std::numeric_limits<double>::infinity();
  double progress_since = 0.0;
  std::vector<PointId> replanned_at;
  int replans_again = 0;
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

// A Route query. Route depends on the map and these alone, so its answers can be kept: a
// waiting robot asks the same question every step until something moves.
struct RouteQuery {
  PointId from, to, ban_point;
  int ban_corridor, ban_guard;
  double bound;  // not part of the memo's key (RouteAnswer)
  int keep_off = -1;  // a second corridor banned (the one its last detour went round, StickyCorridor)
  bool operator==(const RouteQuery& o) const {
    return from == o.from && to == o.to && ban_point == o.ban_point && ban_corridor == o.ban_corridor &&
           ban_guard == o.ban_guard && keep_off == o.keep_off;
  }
};
// What a search under `bound` found: the cheapest route (then the answer to every bound at
// least its cost, and none below), or none (the answer to every bound up to this one).
struct RouteAnswer {
  Detour detour;
  double bound = 0.0;
};
struct RouteQueryHash {
  std::size_t operator()(const RouteQuery& q) const;
};

}  // namespace traffic_detail

using traffic_detail::CorridorState;
using traffic_detail::Detour;
using traffic_detail::ControlledRobot;
using traffic_detail::WaitKind;
using traffic_detail::WhyKey;

struct TrafficController::Impl {
  std::shared_ptr<const WarehouseMap> map;
  TrafficControllerConfig config;
  LaneCorridors lanes;
  IntersectionGrants grants{0};
  // Points closer than point_clearance + 2 * max_envelope, with their distance.
  std::vector<std::vector<std::pair<PointId, double>>> near;
  std::vector<int> holder;                 // per point
  // Robots off the floor that still stand somewhere (SetStanding): index and position.
  std::vector<std::pair<std::size_t, Eigen::Vector2d>> standing;
  std::vector<CorridorState> cstate;
  std::vector<ControlledRobot> robots;
  std::unordered_map<std::string, std::size_t> index;
  std::uint64_t route_epochs = 0;  // the last ControlledRobot::route_epoch handed out
  void Touch(ControlledRobot& x) { x.route_epoch = ++route_epochs; }
  // Robot x asks to leave its point at time t: its progress towards its goal
  // (ControlledRobot::progress_*), measured on the bound route table (not without one).
  void NoteProgress(ControlledRobot& x, double t);
  static void ForgetProgress(ControlledRobot& x) { x.progress_goal = kNoPoint; }
  // A detour livelock: re-planned back and forth (three times again at points it had
  // re-planned at) and no closer to its goal for blocked_after.
  bool Livelocked(const ControlledRobot& x, double t) const {
    return x.progress_goal != kNoPoint && x.replans_again >= 3 && t - x.progress_since >= config.blocked_after;
  }
  // A re-plan of robot x (a detour, a back-off) at the point it stands at.
  void Replanned(ControlledRobot& x) {
    ++stats.replans;
    if (std::find(x.replanned_at.begin(), x.replanned_at.end(), x.at) != x.replanned_at.end()) {
      ++x.replans_again;
    } else {
      x.replanned_at.push_back(x.at);
    }
  }
  TrafficStats stats;
  // The map as Search reads it, in flat arrays (built once in Create): per point its position
  // and intersection, its out-arcs (in out_arcs order) from search_begin[p] with their end,
  // corridor and ArcTime.
  struct SearchArc {
    PointId to;
    int corridor;
    ArcId arc;
    double time;
  };
  std::vector<Eigen::Vector2d> point_xy;
  std::vector<int> guard_of;
  std::vector<int> region_of;  // per point: the map free-space region it is in, or -1
  std::vector<std::uint32_t> search_begin;  // point_count() + 1 entries
  std::vector<SearchArc> search_arcs;
  // Dijkstra scratch.
  std::vector<double> dist;
  std::vector<ArcId> via;
  std::vector<std::uint32_t> seen;
  std::uint32_t stamp = 0;
  // SetRouteBound: the table (null: none) and the factor that turns its costs into lower
  // bounds of ArcTime sums (its speed may exceed config.speed).
  std::shared_ptr<const RouteTable> bound_routes;
  double bound_scale = 1.0;
  // BoundCost's memo: bound_routes' costs to lower_to, for the points stamped lower_stamp
  // (a search's heuristic asks each point it relaxes, CheapestCost then Search again).
  std::vector<double> lower_memo;
  std::vector<std::uint32_t> lower_seen;
  std::uint32_t lower_stamp = 0;
  PointId lower_to = kNoPoint;
  double BoundCost(PointId v, PointId to);
  // A*'s open list (a binary heap on key, then point; h kept for the staleness test).
  struct OpenItem {
    double key;
    PointId point;
    double h;
  };
  std::vector<OpenItem> open;
  // ResolveDeadlocks' scratch: the walk each robot was reached on, the current wait chain.
  std::vector<std::uint32_t> deadlock_walk;
  std::vector<std::size_t> deadlock_path;
  std::vector<int> corridor_scratch;  // ReconcileCorridors' copy of a robot's corridors
  // Route's recent answers (cleared when full: kRouteMemo entries bound its memory).
  static constexpr std::size_t kRouteMemo = 4096;
  std::unordered_map<traffic_detail::RouteQuery, traffic_detail::RouteAnswer, traffic_detail::RouteQueryHash> route_memo;

  const WarehouseMap& M() const { return *map; }
  double ArcTime(ArcId a) const {
    const Arc& arc = M().arc(a);
    const double v = arc.max_speed > 0 ? std::min(config.speed, arc.max_speed) : config.speed;
    return arc.length / v;
  }
  int CorridorOf(ArcId a) const { return lanes.CorridorOfArc(M(), a); }
  int Priority(std::size_t r) const {
    const ControlledRobot& x = robots[r];
    return x.working ? 2 : (x.loaded ? 1 : 0);
  }
  // True when robot a yields to robot b (a has lower priority).
  bool Lower(std::size_t a, std::size_t b) const {
    const int pa = Priority(a), pb = Priority(b);
    if (pa != pb) return pa < pb;
    if (config.priority_by_release && robots[a].rank != robots[b].rank) return robots[a].rank > robots[b].rank;
    return a > b;
  }
  // Robots of one formation (a shared group) may come closer than eps1.
  static bool Mates(const ControlledRobot& a, const ControlledRobot& b) {
    for (int g : {a.group, a.group2, a.group3}) {
      if (g > 0 && (b.group == g || b.group2 == g || b.group3 == g)) return true;
    }
    return false;
  }
  std::string Name(PointId p) const { return "'" + M().point(p).name + "'"; }

  // Points, corridors, grants and waits (traffic_controller_requests.cpp).
  int PointBlocker(PointId q, std::size_t r) const { return PointBlocker(q, r, robots[r].envelope); }
  // The point robot r's last detour went round while the robot that held it holds it still
  // (else kNoPoint, and forgotten), to be avoided by its next detours too. Found on a dense
  // grid: a robot that went round a point held by a robot standing at a drop met a third
  // head-on on the way, and the head-on's detour, shorter than the one it drove, led back to
  // the held point: round and back every 8 s until it was blocked.
  PointId StickyBan(std::size_t r);
  // The corridor r's last detour from a corridor wait went round (-1: none), while the robot
  // it waited on still holds it and r is not in it nor bound for a point in it: detours,
  // head-on detours and back-offs keep off it too (found on a dense grid with the time-window
  // planner: a robot backed off from one corridor held the other way straight into the
  // corridor its detour had just gone round, and back, for 120 s, while a robot waiting for it
  // to clear was blocked).
  int StickyCorridor(std::size_t r);
  // With r's envelope taken as `envelope` (an agent about to be placed with another one).
  int PointBlocker(PointId q, std::size_t r, double envelope) const;
  int CorridorBlocker(int c, int d, std::size_t r) const;
  // A robot (not r's teammate) standing in, or driving into, the free-space region of point q,
  // when r stands outside it; else -1. A region holds one robot at a time: a four-wheel-steer
  // robot's plan there is poses (hybrid A*) between the graph points it is named after, so the
  // points' clearance does not keep another robot in the region clear of its true path (found
  // through the service: a robot that stepped aside into a bay came 0.35 m from one turning
  // there).
  int RegionBlocker(PointId q, std::size_t r) const;
  void HoldCorridor(int c, int d, std::size_t r);
  void DropCorridor(int c, std::size_t r);
  void ReconcileCorridors(std::size_t r);
  void ReleaseGuard(std::size_t r);
  // A robot placed on a point of an intersection holds its grant at once (it stands inside:
  // no crossing movement may be granted around it until it has left); placed elsewhere, it
  // lets go of one it held. OccupyGuard(r, g): it stands inside intersection g (-1: none).
  void OccupyGuard(std::size_t r) { OccupyGuard(r, M().IntersectionOf(robots[r].at)); }
  void OccupyGuard(std::size_t r, int g);
  void ClearWait(ControlledRobot& x);
  TrafficDecision Wait(std::size_t r, WaitKind kind, int on, double t, std::string why);
  // Wait with a reason made by `why()` only when `key` differs from the one it was last made
  // from (the text depends on the key alone).
  template <typename Why>
  TrafficDecision WaitFor(std::size_t r, WaitKind kind, int on, double t, const WhyKey& key, Why why) {
    ControlledRobot& x = robots[r];
    if (x.why_key == key) return Wait(r, kind, on, t, std::move(x.why), key);
    return Wait(r, kind, on, t, why(), key);
  }
  TrafficDecision Wait(std::size_t r, WaitKind kind, int on, double t, std::string why, const WhyKey& key);

  double RouteCost(const ControlledRobot& x) const;
  double ClearTime(std::size_t h, int c, double now) const;
  Status Assign(std::size_t r, std::vector<PointId> points);
  TrafficDecision HeadOn(std::size_t r, int c, int oncoming, double t);  // traffic_controller_head_on.cpp
  int PriorityOncoming(std::size_t r, int c, int d, double t) const;
  TrafficDecision Request(std::size_t r, double t);
  TrafficDecision Check(std::size_t r, PointId q, double t);
  // The agent at work that r would stand behind with no way around it if it drove on: along
  // r's route from index `from` (while each point has no other way out), an agent standing at
  // work on a point r needs, working beyond blocked_after from t - or, with box_exit, at all on
  // the point at `from` (the exit of the intersection r would enter). -1: none.
  int WorkAhead(std::size_t r, std::size_t from, bool box_exit, double t) const;
  // True when a robot at p may leave it other than to `next`: by an arc to a point that is not
  // a dead end leading only back to p (a dock beside an aisle is no way around).
  bool TurnOff(PointId p, PointId next) const;
  void Arrived(std::size_t r);
  void Remove(std::size_t r);

  // Detours, back-off, sidings and deadlocks (traffic_controller_deadlocks.cpp).
  Detour Route(PointId from, PointId to, PointId ban_point, int ban_corridor, int ban_guard,
               double bound = kInf, int keep_off = -1);
  Detour Search(const traffic_detail::RouteQuery& q);  // Route without the memo
  double CheapestCost(const traffic_detail::RouteQuery& q);  // Search's route cost, by bound_routes
  // Whether a search under q's bans may take arc a (its point, corridor and intersection).
  bool Allowed(const SearchArc& a, const traffic_detail::RouteQuery& q) const {
    if (a.to == q.ban_point) return false;
    if (q.ban_corridor >= 0 && a.corridor == q.ban_corridor) return false;
    if (q.keep_off >= 0 && a.corridor == q.keep_off) return false;
    return !(q.ban_guard >= 0 && guard_of[static_cast<std::size_t>(a.to)] == q.ban_guard && a.to != q.to);
  }
  bool StartAllowed(std::size_t r, const std::vector<PointId>& points) const;
  bool TryDetour(std::size_t r, PointId ban_point, int ban_corridor, int ban_guard,
                 bool need_free_first_hop);
  // Steps r back to a free neighbour outside `keep_out` (the corridor a robot waiting for r
  // must enter, -1: none) and re-plans from there.
  bool TryBackOff(std::size_t r, PointId avoid, PointId ban_point, int keep_out = -1);
  // Routes r (with no route of its own) out of corridor `corridor`, whose interior it stands
  // in, to the nearest point beyond it, through free points and never through `avoid` or
  // `ban_point`; false when none is in reach.
  bool LeaveCorridor(std::size_t r, PointId avoid, PointId ban_point, int corridor);
  // The corridor robot w's next arc runs in (the one it waits to enter, or holds), else -1.
  int NextCorridor(std::size_t w) const;
  bool Siding(PointId p) const;
  bool StepAside(std::size_t r, const std::vector<PointId>& keep_clear);
  // An idle robot standing next to idle robot h steps aside (keeping `keep` and h's point
  // clear), so that h can move next; false when none can.
  bool MakeRoom(std::size_t h, const std::vector<PointId>& keep);
  bool StandingIdle(std::size_t r) const;
  bool BreakCycle(const std::vector<std::size_t>& members, double t);
  // Wang2019 §3.3 case ② (traffic_controller_give_way.cpp): robot w waits for robot h and each
  // one's route ahead passes where the other stands; h may give way to w (the option is on, h
  // waits, stands, is alone and not at work, and has the lower priority); GiveWay moves it to
  // the nearest free point off w's way (OnWayOf) with the route on to its goal from there;
  // GivingWayTo: the robot r waits for, giving way, off its way (-1: none any more).
  bool HeadOnPair(std::size_t w, std::size_t h) const;
  bool OnWayOf(std::size_t w, PointId p, double clearance) const;
  bool MayGiveWay(std::size_t h, std::size_t w, double t) const;
  bool GiveWay(std::size_t h, std::size_t w, double t);
  int GivingWayTo(std::size_t r, double t);
  std::size_t ResolveDeadlocks(double t);
};

}  // namespace dispatch::engine
