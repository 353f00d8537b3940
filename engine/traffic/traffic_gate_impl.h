// TrafficGate's state, shared by traffic_gate.cpp (plans, effects, interface),
// traffic_gate_solo.cpp (solo agents), traffic_gate_distances.cpp
// (the minimum distance), traffic_gate_teams.cpp (formations),
// traffic_gate_breakup.cpp (a formation breaking up before its drop),
// traffic_gate_leaving.cpp (a formation leaving its drop) and traffic_gate_rejoin.cpp
// (formations formed again after a restart). Internal to the gate; see
// traffic_gate.h for the model.
#pragma once

#include <algorithm>
#include <array>
#include <functional>
#include <limits>
#include <optional>
#include <map>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

#include "engine/traffic/traffic_gate.h"

namespace dispatch::engine {

// The formation segment of one order in a robot's plan (GateImpl::SpanOf).
struct GateTeamSpan {
  long join = -1, first_pick = -1, drop = -1;
  PointId rendezvous = kNoPoint;
  std::uint64_t seq_first_pick = 0, seq_drop = 0;
};

// The formation orders a robot counts as one with (GateImpl::TeamKeys): distinct, the set ones
// first ("": none).
using GateTeamKeys = std::array<std::string, 3>;

// One robot as the gate knows it.
struct GateBot {
  std::string id;
  int ctl = -1;  // its controller agent (on the floor unless it is in a team or was removed)
  bool connected = false;
  bool removed = false;  // cleared off the floor while offline (TrafficGate::Remove), until Connect
  bool synced = false;  // a state report since it connected (its last waypoint is known)
  GatePlan plan;
  std::uint64_t plan_version = 0;  // counts the plan's changes (Reindex)
  // Driving to run_next from plan index run_idx of plan version run_version, clear of the point
  // behind, it was released everything it may drive to there (StepSolo: nothing to do).
  PointId run_next = kNoPoint;
  long run_idx = -2;
  std::uint64_t run_version = 0;
  long idx = -1;                 // plan index of the last waypoint reached (-1: none)
  std::uint64_t reached_seq = 0;  // highest waypoint sequence reached
  double reach_time = 0.0;        // when it reached idx
  std::uint64_t released = 0;     // highest waypoint sequence released
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();
  bool has_xy = false;
  bool left = false;      // LeftPoint done for the current drive
  bool held = false;      // a Hold was sent for the current wait
  std::string hold_reason;  // the reason of that Hold
  bool resume_pending = false;  // reconnected: resend Resume if it was held
  bool blocked = false;   // kBlocked reported for the current wait
  bool stepped_aside = false;
  // Paused by an operator (issue 18 §4; "": not paused): nothing more is released to it (or to
  // its team); it stops at the last waypoint released and is held there until resumed.
  std::string paused_by;
  // Since when it has found the rendezvous point of formation `forming` occupied (JoinTeam),
  // and when it last tried (a try after a pause starts the clock again).
  std::string forming;
  double forming_since = 0.0, forming_last = 0.0;
  PointId home = kNoPoint;  // the parking point it first connected at
  std::string team;       // the formation order whose team it has joined ("": none)
  // The team it left (at point former_at), until it has driven out of the team's envelope.
  std::string former_team;
  PointId former_at = kNoPoint;
  // The teams it had left before former_team, while it had not driven off from those either
  // (a member of several teams in turn at one place), newer first; cleared with former_team.
  std::string older_former, oldest_former;
  std::uint64_t leave_seq = 0;  // leaving a team: the waypoint it was placed at (to reach first)
  // The team it counted as one with (TeamKeys()[0]) when its controller groups were last set.
  std::string approach;
  std::vector<PointId> leg;  // the controller route as last set or adopted
  // The controller's RouteEpoch when leg was last seen to be its remaining route (0: not
  // known; every write to leg sets it): LegIsRemainingRoute.
  std::uint64_t leg_epoch = 0;
  long leg_stop = -1;     // plan index of the leg's last waypoint (-1: none)
  bool leg_stale = true;  // recompute the leg before the next request
  // Waiting for its turn at a point (PlanExecution::kOrder): since when it has stood at plan index
  // order_idx with point order_point next.
  long order_idx = -2;
  PointId order_point = kNoPoint;
  double order_since = 0.0;
  // Per formation order of the plan, its segment (none: no pick of it left); kept by Reindex.
  std::map<std::string, std::optional<GateTeamSpan>> spans;
};

// One formation team (Chu2024 §3.2): the members, leader first, and their shared agent.
struct GateTeam {
  enum class Phase { kForming, kMoving, kLeaving };
  std::string order;
  std::vector<std::string> members;
  int ctl = -1;  // the team agent (pooled controller index)
  Phase phase = Phase::kForming;
  std::set<std::string> joined;
  long k = 0;        // formation index of the first waypoint of the run the team stands at
  long next_k = -1;  // formation index of the first waypoint at the point it drives to
  std::vector<PointId> leg;
  long leg_stop = -1;  // formation index of the leg's stop
  bool leg_stale = true;
  bool left = false;
  bool blocked = false;
  PointId drop = kNoPoint;  // where the team leaves from
  // Its order went before the drop and it leaves the point it stood on (DissolveTeam): `drop`
  // is that point, and the order may come back to a new team once this one is gone.
  bool broken = false;
  double broken_since = -1.0;  // when it began to leave (StepTeams; -1: not yet stepped)
  std::map<std::string, std::uint64_t> drop_seq;  // member -> sequence of its drop waypoint
};

struct GateImpl {
  using TeamSpan = GateTeamSpan;

  GateImpl(std::shared_ptr<const WarehouseMap> map, std::shared_ptr<const RouteTable> routes,
           TrafficControllerConfig config, TrafficController ctl);

  std::shared_ptr<const WarehouseMap> map;
  std::shared_ptr<const RouteTable> routes;
  TrafficControllerConfig config;
  TrafficController ctl;
  std::map<std::string, GateBot> bots;  // never erased: bot_index points into it
  std::unordered_map<std::string, GateBot*> bot_index;  // bots by id in one hash lookup
  // bots in id order as a flat array: every step walks all of them (Step, SampleDistances)
  // without chasing the map's tree nodes.
  std::vector<GateBot*> in_order;
  // ctl.RemainingRouteIs(agent, b.leg) for a solo robot on the floor, without reading either
  // route while the controller's route epoch is the one it was seen equal at (every step asks).
  bool LegIsRemainingRoute(GateBot& b) {
    const auto r = static_cast<std::size_t>(b.ctl);
    const std::uint64_t epoch = ctl.RouteEpoch(r);
    if (b.leg_epoch == epoch) return true;
    if (!ctl.RemainingRouteIs(r, b.leg)) return false;
    b.leg_epoch = epoch;
    return true;
  }
  // b.leg = the controller's remaining route (equal at this epoch).
  void CopyLeg(GateBot& b) {
    const auto r = static_cast<std::size_t>(b.ctl);
    ctl.CopyRemainingRoute(r, b.leg);
    b.leg_epoch = ctl.RouteEpoch(r);
  }
  GateBot* Find(const std::string& id) {
    auto it = bot_index.find(id);
    return it == bot_index.end() ? nullptr : it->second;
  }
  const GateBot* Find(const std::string& id) const {
    auto it = bot_index.find(id);
    return it == bot_index.end() ? nullptr : it->second;
  }
  // The robot's entry, made (and indexed, with its id) if new.
  GateBot& Get(const std::string& id) {
    if (GateBot* b = Find(id)) return *b;
    GateBot& b = bots[id];
    b.id = id;
    bot_index.emplace(id, &b);
    in_order.insert(std::lower_bound(in_order.begin(), in_order.end(), id,
                                     [](const GateBot* x, const std::string& k) { return x->id < k; }),
                    &b);
    return b;
  }
  std::map<std::string, GateTeam> teams;  // by formation order id
  std::set<std::string> finished_teams;   // formations that have left their drop point
  std::uint64_t leaving_ended = 0;        // teams erased while leaving (TrafficGate::LeavingEnded)
  std::set<std::string> strays;  // broken-up teams' members not back on the floor (PlaceStrays)
  std::vector<std::size_t> team_pool;     // removed team agents, reusable
  std::size_t team_agents = 0;            // team agents ever added (their ids)
  MinDistance min_distance;
  // SampleDistances' scratch, kept between calls (no allocation per sample): per robot its
  // position (clamped onto the grid), 1 m cell, index and team keys once needed; the grid over
  // the floor (built on first use) with a list head per cell and a next link per robot.
  struct DistanceItem {
    Eigen::Vector2d xy;  // the robot's position (not clamped)
    long long cx, cy;    // its cell
    const GateBot* bot;
    Eigen::Vector2d in_cell;  // xy relative to its cell's low corner (NaN: off the grid)
  };
  std::vector<DistanceItem> distance_items;
  // Per item, its team keys once a close pair needed them (valid while the stamp is the
  // sample's).
  std::vector<GateTeamKeys> distance_keys;
  std::vector<std::uint32_t> distance_keys_stamp;
  std::uint32_t distance_stamp = 0;
  Eigen::Vector2d distance_origin = Eigen::Vector2d::Zero();
  std::size_t distance_cols = 0, distance_rows = 0;
  std::vector<int> distance_head, distance_next;
  std::vector<std::string> notes;  // TrafficGate::TakeNotes
  std::vector<PointId> order_route;  // AwaitsItsTurn's scratch: the robot's remaining route
  // The earliest planned departure (dispatcher seconds) a standing robot or team waits for,
  // seen by the last Step: nothing else may change by then (+inf: none).
  double next_wake = std::numeric_limits<double>::infinity();
  void WakeAt(double t) { next_wake = std::min(next_wake, t); }
  // Per point: a service point other than parking is this point or within point_clearance
  // of it (an idle robot standing there keeps others from serving).
  std::vector<bool> blocks_service;
  static int GroupOf(const std::string& order);  // the controller group of a formation

  // Plans.
  static long IndexOf(const GateBot& b, std::uint64_t seq);
  // Last index of the run of waypoints at point p starting at `from` (at most `limit`);
  // from - 1 when waypoint `from` is not at p.
  static long RunEnd(const GateBot& b, long from, PointId p, long limit);
  // How far a solo robot granted `next` (from the point `at` it stands on) is released: the
  // waypoints still ahead of it at `at` (a rewrite's anchor there, not yet reported), then the
  // run at `next`.
  static long GrantedRunEnd(const GateBot& b, PointId at, PointId next);
  double Departure(const GateBot& b, long i) const;
  static bool IsStop(const Waypoint& w);
  // The formation segment of `order` in b's plan (from b.spans for its formation orders).
  static std::optional<TeamSpan> SpanOf(const GateBot& b, const std::string& order);
  static std::optional<TeamSpan> FindSpan(const GateBot& b, const std::string& order);
  long NextJoin(const GateBot& b, long from, std::string* order) const;
  void Reindex(GateBot& b);  // after b.plan changed: its index, idx and spans
  // `member` >= 0: b is that slot of a moving formation (StepTeamsAfterDeadlocks): its
  // waypoints are its slot along the route (eq. (9)), turning in place about the centre where
  // the heading changes, as BuildFormationPlans plans them.
  long RewriteLeg(GateBot& b, long cut, const std::vector<PointId>& route, long resume, double t,
                  std::vector<GateEffect>& out, int member = -1);

  // Effects.
  void Release(GateBot& b, long upto, int intersection, std::vector<GateEffect>& out);
  // A kRelease of b's current horizon (a Resume when it was held).
  void SendRelease(GateBot& b, int intersection, std::vector<GateEffect>& out);
  void Hold(GateBot& b, const std::string& why, std::vector<GateEffect>& out);
  // Held because paused (its Hold says so, also when it was held for something else before).
  void HoldPaused(GateBot& b, std::vector<GateEffect>& out);
  // Reports b blocked (once per blocked spell) and holds it: `why` names what it waits for.
  void Block(GateBot& b, const std::string& why, std::vector<GateEffect>& out);

  // Solo agents (traffic_gate_solo.cpp).
  bool OnFloor(const GateBot& b) const;
  bool PlaceBot(GateBot& b, PointId at);
  bool PlaceNear(GateBot& b);
  // Former members of a formation that is gone, off the floor because the point at their slot
  // was a teammate's: placed as soon as it is free, before anyone else requests it.
  void PlaceStrays();
  void StepSolo(GateBot& b, double t, std::vector<GateEffect>& out);
  void RequestSolo(GateBot& b, double t, std::vector<GateEffect>& out);
  // PlanExecution::kOrder (traffic_gate_order.cpp): true when standing robot
  // b waits for a robot planned to pass its next point before it (held, saying so).
  bool AwaitsItsTurn(GateBot& b, double t, std::vector<GateEffect>& out);
  void AdoptRoute(GateBot& b, double t, std::vector<GateEffect>& out);
  void OnReached(GateBot& b, std::uint64_t seq, double t);
  GateTeamKeys TeamKeys(const GateBot& b) const;
  // b's controller groups (and b.approach) from its team keys.
  void SetGroups(GateBot& b);
  // No team keys: in no team, left none that is still near, no formation order in its plan.
  static bool Alone(const GateBot& b) { return b.team.empty() && b.former_team.empty() && b.plan.teams.empty(); }
  void SampleDistances(double t);

  // Teams (traffic_gate_teams.cpp).
  void SyncTeams(GateBot& b);
  void JoinTeam(GateBot& b, const std::string& order, double t, std::vector<GateEffect>& out);
  bool TeamAgentOnFloor(const GateTeam& team) const;
  // Puts the team's agent (pooled or new) on `p`; false when the point is taken.
  bool PlaceTeamAgent(GateTeam& team, PointId p, double t);
  // After a restart (traffic_gate_rejoin.cpp).
  // The formation order whose segment b is inside (from the rendezvous run to the drop)
  // while its team is still forming and b is not in it: after a restart, where the gate's
  // teams are gone but the members' plans and positions are not.
  std::optional<std::pair<std::string, TeamSpan>> SpanAround(const GateBot& b) const;
  // Forms the team again there (SpanAround): while it assembles, b joins as at the approach;
  // once it has moved off the first pick, when every member has reported, the team agent
  // goes to the least advanced member's point (at the drop it then leaves as usual). If a
  // member has left the drop already, the others become former members (exempt from one
  // another until they have driven off) and b goes on alone: false.
  bool RejoinTeam(GateBot& b, const std::string& order, const TeamSpan& span, double t,
                  std::vector<GateEffect>& out);
  // Teams' phases (traffic_gate_teams.cpp).
  void StepTeams(double t, std::vector<GateEffect>& out);
  void StepTeamsAfterDeadlocks(double t, std::vector<GateEffect>& out);
  void BreakTeam(GateTeam& team);
  bool DissolveTeam(GateTeam& team);  // true: gone (BreakTeam); false: it leaves (kLeaving)
  // b leaves (or never joins) `order`'s team at `at` (kNoPoint: until its next point): exempt
  // from its members until it has driven off; of the former teams it still had, two stay
  // (older_former, oldest_former): those with a member closer to b than eps1 first, then
  // those with one beside it (TeammateBeside), then the newer.
  void BecomeFormer(GateBot& b, const std::string& order, PointId at);
  // A robot of team `order` (in it, approaching it or having left it) other than b stands
  // within the formation's envelope (eps1 + the formation's radius) of b, or of the point b
  // drives to.
  bool TeammateBeside(const GateBot& b, const std::string& order) const;
  // The distance from b to the nearest other robot of team `order` (infinity: none known).
  double TeammateDistance(const GateBot& b, const std::string& order) const;
  // The distance from p to the nearest robot of team `order` other than b (infinity: none).
  double TeamDistanceFrom(const Eigen::Vector2d& p, const GateBot& b, const std::string& order) const;
  bool StepLeaving(GateTeam& team, double t, std::vector<GateEffect>& out);  // traffic_gate_leaving.cpp
};

struct TrafficGate::Impl : GateImpl {
  using GateImpl::GateImpl;
};

}  // namespace dispatch::engine
