// TrafficController: the online, reservation-based local traffic layer (SPEC §3.5; Chu2024
// §3.3 crossing rule; Wang2019 §3.2 node control and §3.3 head-on conflicts), driven only by
// what robots report (which point they stand at, which arc they drive) and the time. The same
// object runs inside the order-stream simulator and, later, the server's dispatcher loop.
//
// Resources and rules (a robot may depart from point p to the next point q of its route only
// when Request() says kGo; it then holds q until it leaves it):
//  - Points: each point is held by at most one robot (the one standing there, or driving
//    towards it, or driving away from it until it is point_clearance past it: LeftPoint). A point is free only when no OTHER robot holds it or any point closer than
//    `point_clearance` to it (Chu2024 eps1; e.g. a pick dock 0.5 m off a lane point).
//    Robots of equal speed then never get closer than the point spacing (>= eps1).
//  - Intersections (Chu2024 eqs. (13)-(15)): entering the inner region I_w needs a grant for
//    the movement (point before, point after) from IntersectionGrants (FIFO, exclusive
//    between different movements); released when the robot arrives past I_w.
//  - Single-lane corridors (Wang2019 §3.3, LaneCorridors): reserved for one direction at a
//    time, from the point BEFORE the corridor's end point (look-ahead of one arc), so a robot
//    waiting to enter never stands on the corridor's end that an oncoming robot must leave by.
//    A corridor with a service point inside (robots stop and may turn back there) takes one
//    robot at a time; pure transit corridors take any number in one direction.
//    A robot that meets a corridor held the other way (a head-on conflict) compares the
//    expected wait (the oncoming robots' time to leave it) with the extra time of a detour
//    avoiding it and takes the faster (HeadOnPolicy::kChooseFaster); the decision is logged.
//  - Waits (Wang2019 §3.2 steps 3-4): waiting on a corridor longer than T_w1, or on a held
//    point / grant longer than T_w2, re-plans a detour if one exists; a robot that has waited
//    `blocked_after` with no alternative is reported blocked (kBlocked, with the reason).
//  - Priority: a robot that works (picks/drops: SetWorking) is never asked to yield; among
//    the others loaded robots (SetLoaded) come before empty ones, then (priority_by_release,
//    Wang2019 §3.2) the earlier task release (SetRank), then lower index.
//  - Deadlock (ResolveDeadlocks): the wait-for graph has an edge from every waiting robot to
//    one robot it waits for (point holder, oncoming corridor holder, or grant holder); each
//    node has out-degree <= 1, so cycles are found in O(robots). In each cycle the lowest-
//    priority member that can act re-plans a detour avoiding what it waits for, or backs off
//    to a free neighbouring point and re-plans from there (a member that could not act is
//    retried after 1 s; detours are bounded to blocked_after beyond the current route's
//    cost, A* with the straight-line heuristic). An idle robot (no route) that
//    somebody waits for is sent to a siding off the waiter's route (StepAside, "nudge"), else
//    backs off, else an idle robot boxing it in steps aside first (MakeRoom).
//
// Costs: Request/Arrived are O(route look-ahead + clearance neighbours); ResolveDeadlocks is
// O(robots); detours run one bounded A* over the map (reused buffers). No all-pairs work.
// Deterministic. Not thread-safe: one owner (the simulator or the dispatcher loop).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "engine/common/result.h"
#include "engine/map/warehouse_map.h"
#include "engine/routing/route_table.h"
#include "engine/traffic/intersection_grants.h"
#include "engine/traffic/lane_corridors.h"

namespace dispatch::engine {

enum class HeadOnPolicy {
  kChooseFaster,  // Wang2019 §3.3: wait or re-plan, whichever is expected faster
  kAlwaysWait,    // the paper's "single waiting strategy" (for comparison, §4.3)
  kAlwaysReplan,  // always detour when a detour exists
};

// When the TrafficGate asks the controller for a standing robot's next point. Robots leave a
// waypoint no earlier than its planned departure (eta + dwell) in every case: that is the
// robots' side of the protocol. Wang2019 §3.2: the offline stage (the time-window planner)
// gives each robot a route with the times it passes each point; its online stage controls the
// robots at the points.
enum class PlanExecution {
  // At the robot's planned departure: until then the point ahead stays free for others.
  kTimes,
  // As soon as its work at the waypoint is done: a robot that waits out its plan's time holds
  // the point it goes to next (granted, as any other) until it leaves.
  kClaim,
  // kClaim, and each point is passed in the plans' order (Wang2019 §3.2 steps 1-3,
  // traffic_gate_order.cpp): a robot waits (at most T_w1) while one planned to pass its next
  // point before it is on its way there; one that is not loses its turn.
  kOrder,
};
const char* PlanExecutionName(PlanExecution execution);  // "times", "claim", "order"
std::optional<PlanExecution> ParsePlanExecution(std::string_view name);

// Defaults: Wang2019 names T_w1 / T_w2 but gives no values. T_w1 = 10 s is about the time a
// robot needs to drive a 10-cell aisle at 1 m/s; T_w2 = 20 s is longer than a pick (5 s) plus
// clearing the next cells, so queues behind a working robot do not re-plan needlessly.
// blocked_after = 120 s: like SimConfig::max_wait of the plan simulator.
struct TrafficControllerConfig {
  double speed = 1.0;            // m/s, robots' cruise speed (arc max_speed caps it)
  double point_clearance = 0.6;  // m: points closer than this conflict (eps1)
  double t_w1 = 10.0;            // s: corridor (head-on) wait before re-planning
  double t_w2 = 20.0;            // s: held point / grant wait before re-planning
  double blocked_after = 120.0;  // s of waiting with no alternative -> blocked
  // Largest extra clearance of an agent (SetEnvelope): a formation's D_f = 0.4 / sqrt(3) m.
  double max_envelope = 0.25;
  bool intersection_grants = true;
  HeadOnPolicy head_on = HeadOnPolicy::kChooseFaster;
  // Wang2019 §3.2: between robots of one class (working, loaded, the rest) the one whose task
  // was released earlier has priority (SetRank); false: the lower index, as before.
  bool priority_by_release = false;
  // Wang2019 §3.3 case ①: a robot about to enter a free single-lane corridor gives way (waits
  // or detours, as on a head-on) to a robot of higher priority that would enter it from the
  // other end before it is through; false: the corridor goes to whoever claims it first.
  bool head_on_priority = false;
  // Wang2019 §3.3 case ②: of two robots head-on where one stands waiting, a waiting robot of
  // lower priority drives to the nearest free point off the other's way and waits there until
  // it has passed (at most T_w1); false: the wait-for cycle's detour or one-point back-off.
  bool head_on_give_way = false;
  // How the TrafficGate executes the robots' plans (PlanExecution).
  PlanExecution execution = PlanExecution::kTimes;
  Status Validate() const;
};

enum class TrafficDecision { kGo, kWait, kReplanned, kBlocked };

// One head-on decision (Wang2019 §3.3 / §4.3): who met whom, both estimates, the choice.
struct HeadOnRecord {
  double t = 0.0;
  std::string robot, oncoming;
  double wait_estimate = 0.0;   // s until the oncoming robots have left the corridor
  double replan_extra = 0.0;    // s a detour adds (+inf: none; under kChooseFaster also
                                // "none faster than waiting": that search is bounded)
  bool replanned = false;
};

struct TrafficStats {
  std::size_t replans = 0;             // detours taken (head-on, timeouts, deadlocks)
  std::size_t grants = 0;              // intersection grants issued
  std::size_t deadlocks_resolved = 0;  // wait-for cycles broken
  std::size_t nudges = 0;              // idle robots stepped aside
  std::size_t head_on_conflicts = 0;
  std::size_t give_ways = 0;           // waiting robots moved off a higher one's way (case ②)
  std::vector<HeadOnRecord> head_on;   // first 1000 decisions
};

class TrafficController {
 public:
  static Result<TrafficController> Create(std::shared_ptr<const WarehouseMap> map,
                                          const TrafficControllerConfig& config = {});
  TrafficController(TrafficController&&) noexcept;
  TrafficController& operator=(TrafficController&&) noexcept;
  ~TrafficController();

  // Places a robot standing at `at` (which it holds), in `group` (see SetGroup). Errors:
  // unknown point, point held.
  Result<std::size_t> AddRobot(const std::string& id, PointId at, int group = 0);
  std::size_t robot_count() const;
  const std::string& robot_id(std::size_t r) const;

  // A table of this map's shortest travel times, to bound detour searches: a bounded search
  // skips points from which even the unobstructed route cannot arrive within its bound. The
  // searches' answers are unchanged (only points that cannot be on such a route are skipped);
  // a failing search no longer sweeps everything within its bound. Ignored (searches as
  // without) for a table of another map or with turn penalties (its costs are then no lower
  // bound of the controller's arc times); null: none.
  void SetRouteBound(std::shared_ptr<const RouteTable> routes);

  // The robot's route from where it stands: points[0] must be its point, consecutive points
  // joined by arcs. Withdraws pending grant requests. Errors: bad route.
  Status SetRoute(std::size_t r, std::vector<PointId> points);
  // Remaining route: the point it stands at (or drives to) and the rest.
  std::vector<PointId> RemainingRoute(std::size_t r) const;
  // out = RemainingRoute(r), in out's own storage (no allocation once it is large enough).
  void CopyRemainingRoute(std::size_t r, std::vector<PointId>& out) const;
  // RemainingRoute(r) == route, without copying the route (the gate asks every step).
  bool RemainingRouteIs(std::size_t r, const std::vector<PointId>& route) const;
  // A number that changes whenever the remaining route may have changed (a route set, a point
  // reached, the robot removed or placed) and is never the same for two robots: a caller that
  // saw RemainingRouteIs(r, route) at one epoch knows it still holds while the epoch does.
  std::uint64_t RouteEpoch(std::size_t r) const;
  bool HasRoute(std::size_t r) const;  // some point is left to drive to
  PointId At(std::size_t r) const;     // the point it stands at / last left
  PointId Next(std::size_t r) const;   // the point it drives to, or kNoPoint while standing
  // True when p is inside a corridor that takes one robot at a time (a service point inside):
  // a robot standing there closes the whole corridor.
  bool InExclusiveCorridor(PointId p) const;
  // Working (picking/dropping) until `work_end` (s): top priority, never asked to yield; the
  // remaining work counts in oncoming robots' wait estimates.
  void SetWorking(std::size_t r, bool working, double work_end = 0.0);
  void SetLoaded(std::size_t r, bool loaded);
  // The release time of robot r's task (+infinity: none, the lowest); read when
  // priority_by_release is set.
  void SetRank(std::size_t r, double release_time);
  // Idle: no work assigned. Only idle robots are nudged aside for others.
  void SetIdle(std::size_t r, bool idle);
  // Robots sharing a group (> 0; 0 = none), e.g. the members of a formation assembling at
  // its rendezvous or leaving its drop point (Chu2024 §3.2), do not keep point_clearance from
  // one another: a point is still held by one robot at a time, but its near points held by
  // groupmates do not block. A robot may be in three groups (leaving one team or two in turn,
  // joining another).
  void SetGroup(std::size_t r, int group, int second = 0, int third = 0);
  // Extra clearance of an agent bigger than one robot (a formation: D_f, its members' distance
  // from the centre; clamped to max_envelope). Two agents' points conflict when closer than
  // point_clearance + both envelopes (Chu2024 eqs. (10)-(12): eps1, eps2, eps3).
  void SetEnvelope(std::size_t r, double extra);

  // The robot stands at At(r) and wants to drive to its next route point at time t.
  // kGo: reservations taken, drive the arc (Next(r)) and call Arrived; kWait: stay (why() says
  // why); kReplanned: the route changed, ask again; kBlocked: no alternative for too long.
  TrafficDecision Request(std::size_t r, double t);
  // The driving robot is at least point_clearance past At(r): releases that point, so a long
  // arc does not keep the point behind it blocked until the robot arrives.
  void LeftPoint(std::size_t r);
  // The robot has reached Next(r): releases the point behind it, corridors and grants it left.
  void Arrived(std::size_t r, double t);
  // Removes the robot from the floor (fault, or it left): releases everything it holds.
  void Remove(std::size_t r);
  // Puts a removed robot back on the floor, standing at `at` with no route (so a long-running
  // owner reuses indices instead of adding robots). Errors: not removed, unknown point, the
  // point (or one within point_clearance) held by another robot.
  Status Place(std::size_t r, PointId at);
  // Robot r (on the floor or not) stands inside the intersection of point `at`: it holds that
  // intersection's grant from now on (IntersectionGrants::Occupy), until it is placed on a
  // point outside it, leaves it or is removed. For a formation breaking up inside an
  // intersection: its members take the grant over before the team's agent lets it go, so no
  // crossing movement is granted in between. No-op when `at` is in no intersection.
  void HoldGrantAt(std::size_t r, PointId at);
  // A robot off the floor (removed) that still stands at `xy` (a formation member left in its
  // slot when its team broke up): no point closer to xy than the pair's clearance is given to
  // a robot that is not its mate, nor is anyone placed there, until it is placed (Place) or
  // cleared (ClearStanding). No-op for a robot on the floor.
  void SetStanding(std::size_t r, const Eigen::Vector2d& xy);
  void ClearStanding(std::size_t r);
  bool removed(std::size_t r) const;
  // The robot holding point p (standing there, driving to it, or not yet clear of it), or -1.
  int HolderOf(PointId p) const;
  // The robot that keeps r (in its group, with envelope `envelope`) off point p: holding it or
  // a point within the pair's clearance; -1 when none.
  int BlockerOf(PointId p, std::size_t r, double envelope) const;
  // The robot r waits on (see ResolveDeadlocks), or -1 when it does not wait.
  int WaitsOn(std::size_t r) const;
  // Seconds r has waited at `t` in its current wait (0 when it does not wait).
  double WaitedFor(std::size_t r, double t) const;
  // A wait the owner sees and the controller cannot: robot r (standing, no route: e.g. a
  // formation's agent waiting for a member to arrive, or for a point to put a member on) waits
  // on robot `other` since t (-1: no longer). ResolveDeadlocks then breaks cycles through it
  // like any other (a working r is never moved; otherwise r may be backed off too).
  void WaitOn(std::size_t r, int other, double t, const std::string& why);
  // Robot r's wait (if any) counts from t for its timeouts (re-plan, blocked_after); what it
  // waits on stays (ResolveDeadlocks still sees it).
  void RestartWaitClock(std::size_t r, double t);
  const std::string& why(std::size_t r) const;  // reason of the last kWait / kBlocked
  // "R3 at 'c9' -> 'c8' route 'c9' 'c8' ... waiting on R4 (point 'c8' held by R4)".
  std::string Describe(std::size_t r) const;

  // Sends an idle robot (no route, not working) to the nearest free "siding": a point that is
  // not a service point, not inside a corridor and not an intersection point, within 40 points
  // (breadth-first), and not within point_clearance + max_envelope of the service point it
  // leaves (so the next robot or formation can be served there). False when it already
  // stands on one or none is found.
  bool StepAside(std::size_t r);
  // The same, also keeping clear `keep_clear` and every point within point_clearance +
  // max_envelope of them.
  bool StepAside(std::size_t r, const std::vector<PointId>& keep_clear);
  // Breaks wait-for cycles and nudges idle robots that block others. Returns cycles broken.
  std::size_t ResolveDeadlocks(double t);

  const TrafficStats& stats() const;
  const LaneCorridors& corridors() const;
  // Intersection grants (guard i = map intersection i): holders and queues by agent id.
  const IntersectionGrants& grants() const;

 private:
  struct Impl;
  explicit TrafficController(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace dispatch::engine
