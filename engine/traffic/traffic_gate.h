// TrafficGate: the TrafficController (SPEC §3.5) driven from what robots report (by the
// server's dispatcher loop), turned into releases of their timed waypoints (issue 5 §1: waypoints
// beyond the next point are sent unreleased; a Grant releases them).
//
// Model. Every connected robot is an agent of the controller standing at (or driving to) a
// map point. A robot's plan is cut into legs: from the point it stands at to its next stop (a
// pick, a drop, a wait with dwell, a formation's rendezvous, or the plan's end). The leg's
// points are the controller route; when the controller says kGo for the next point, the gate
// releases the robot's waypoints up to the last one at that point (kRelease). The robot
// reports WaypointReached at that point: the gate calls Arrived. A robot never asks to leave
// a point before it has reached the last waypoint there and its dwell (work) is over.
// Waiting robots get a Hold with the controller's reason once, and a release with `resume`
// when they may go again. A detour, back-off or nudge of the controller rewrites the leg's
// waypoints (kRewrite: the new plan; the dispatcher stores it and sends a PlanUpdate). A robot
// with no alternative for too long is reported (kBlocked) and stays put.
//
// Formations (Chu2024 §3.2, issue 4 §3). Members drive their approach legs alone. At the
// point before the first pick P a member joins the team: the team's own agent (one agent
// with the formation's envelope) takes P, the member leaves the controller and is released
// into its slot. When all three stand in their slots the team agent drives the centre's route
// (members released in lockstep, team Arrived when all three reached the point); after the
// drop the members go back into the controller one by one at the drop point (the next one
// when the previous has left it; an idle member steps aside to a siding).
//
// Offline robots stay in the controller where they were (they physically block the floor
// until they come back or an operator moves them); on reconnect an agent that stands
// elsewhere is re-placed and its leg re-routed from there.
//
// Minimum distance: the smallest centre distance between two reported robots of different
// agents, kept with the pair and the time. Members of one team count as one agent from their
// approach to the rendezvous until the formation has dissolved: after the drop, until every
// former member has driven out of the team's envelope (eps1 + D_f) around the drop point.
//
// Not thread-safe: one owner (the dispatcher loop). Pure: no clocks, no I/O (TakeNotes
// hands its log lines to the owner).
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/common/result.h"
#include "engine/fleet/plan.h"
#include "engine/map/warehouse_map.h"
#include "engine/routing/route_table.h"
#include "engine/traffic/traffic_controller.h"

namespace dispatch::engine {

struct GateEffect {
  enum class Kind { kRelease, kHold, kRewrite, kBlocked };
  Kind kind = Kind::kRelease;
  std::string robot;
  // kRelease: waypoints up to this sequence may be driven to. intersection >= 0 when the
  // release enters an intersection's inner region (a Grant of that intersection); resume when
  // the robot was held before (send Resume).
  std::uint64_t release_up_to = 0;
  int intersection = -1;
  bool resume = false;
  // kHold, kBlocked: why; kHold: stop at this waypoint sequence.
  std::string reason;
  std::uint64_t hold_at = 0;
  // kRewrite: the robot's whole new plan (same orders and stops); waypoints from
  // from_sequence on are new.
  std::vector<Waypoint> waypoints;
  std::uint64_t from_sequence = 0;
};

// A robot's plan as the dispatcher holds it.
struct GatePlan {
  std::vector<Waypoint> waypoints;  // seq = the robot's life-long waypoint sequence
  std::vector<std::string> order_of;        // per waypoint: the order it serves ("" if none)
  // Formation orders among them: order id -> members, leader first.
  std::map<std::string, std::vector<std::string>> teams;
  std::uint64_t next_sequence = 1;  // the first waypoint sequence never issued
  // The earliest release time of its orders (+infinity: none): its traffic priority under
  // TrafficControllerConfig::priority_by_release.
  double release = std::numeric_limits<double>::infinity();
};

struct MinDistance {
  double distance = std::numeric_limits<double>::infinity();
  std::string a, b;
  double time = 0.0;
};

// A map intersection's grant as robots see it (a formation's grant lists its members).
struct GateIntersection {
  std::vector<std::string> holders;  // robots holding the grant
  std::vector<std::string> waiting;  // robots queued for it, FIFO
};

// What the operator sees of one robot's traffic state.
struct GateRobotState {
  bool held = false;       // a Hold is in force
  std::string reason;      // why, while held
  std::string formation;   // the formation order whose team it is in ("": none)
  // The team's agent stands for it in the controller: false while a member that has joined
  // still drives on its own agent to its slot (until clear of the point it joined from).
  bool moved_by_team = false;
  // The formation orders it counts as one with (CheckSafety's groups), at most three, distinct,
  // the set ones first: the team it is in or drives to join, and the teams it left (at a drop,
  // or broken up; the last two) until it has driven off ("": none).
  std::array<std::string, 3> teams;
  std::string paused_by;  // who paused it ("": not paused)
};

struct GateBot;  // the gate's entry of one robot (traffic_gate_impl.h)

class TrafficGate {
 public:
  static Result<std::unique_ptr<TrafficGate>> Create(
      std::shared_ptr<const WarehouseMap> map,
      std::shared_ptr<const RouteTable> routes, TrafficControllerConfig config);
  ~TrafficGate();
  TrafficGate(const TrafficGate&) = delete;
  TrafficGate& operator=(const TrafficGate&) = delete;

  // The robot's stream is up; it stands near `xy` (nearest point `point`).
  void Connect(const std::string& robot, const Eigen::Vector2d& xy, PointId point);
  // The stream is gone: the robot keeps its place but asks for nothing.
  void Disconnect(const std::string& robot);
  // The robot's plan changed (award, cancel, drop trimmed, restart).
  void SetPlan(const std::string& robot, GatePlan plan);
  // A robot reported blocked (kBlocked) is in service again at t: a block is reported again,
  // and a wait it still stands in is timed from t (reported blocked again after blocked_after).
  // What it waits on stays for the controller's deadlock breaking.
  void Unblock(const std::string& robot, double t);
  // The robot arrived at waypoint `sequence`; `xy`, the pose it reported with the arrival, is
  // where it is seen from then on (a state report may be up to a report interval older, and
  // the minimum distance must not pair one robot's fresh position with another's stale one).
  void Reached(const std::string& robot, std::uint64_t sequence, double t,
               const std::optional<Eigen::Vector2d>& xy = std::nullopt);
  // A state report: position and the last waypoint passed.
  void Report(const std::string& robot, const Eigen::Vector2d& xy, std::uint64_t last_waypoint,
              double t);
  // The robot's entry (nullptr: unknown), for the overloads that skip the id lookup (a report
  // per robot per tick). Valid for the gate's life: entries are never erased.
  GateBot* Entry(const std::string& robot);
  void Reached(GateBot& robot, std::uint64_t sequence, double t, const std::optional<Eigen::Vector2d>& xy);
  void Report(GateBot& robot, const Eigen::Vector2d& xy, std::uint64_t last_waypoint, double t);
  std::uint64_t ReleasedUpTo(const GateBot& robot) const;
  // Runs the controller for every agent and returns what to tell the robots.
  std::vector<GateEffect> Step(double t);
  // When the next Step may release a robot though no report came in: the earliest planned
  // departure (the end of a dwell, or a robot ahead of its plan) the last Step saw robots
  // wait for; +inf when none. The owner steps again then (a release is not a tick late).
  double NextWake() const;
  // Updates the minimum distance from the robots' last reported positions (O(robots)).
  void SampleDistances(double t);

  // False while the robot still stands in a finished formation's slot, waiting to leave it.
  bool Available(const std::string& robot) const;
  // How many teams have ended while leaving their drop (their members Available again): the
  // owner runs an allocation round when it changes (nothing else says they may bid again).
  std::uint64_t LeavingEnded() const;
  // Where a new plan of the robot must start: the point it drives to, or stands at.
  PointId StartPoint(const std::string& robot) const;
  // Highest waypoint sequence released to the robot.
  std::uint64_t ReleasedUpTo(const std::string& robot) const;
  // One entry per map intersection (index = intersection index).
  std::vector<GateIntersection> Intersections() const;
  GateRobotState RobotState(const std::string& robot) const;
  const MinDistance& min_distance() const;
  // Pauses the robot for `by` (an operator's name; "": resumes it), issue 18 §4: nothing more
  // is released to it, or to the team it drives in; it stops at the last waypoint released
  // and is held there ("paused by <by>") until resumed, when the next Step releases it as
  // usual. Its place, plan and orders stay. A robot the gate does not know yet gets an entry
  // (paused from its first connection on, e.g. after a restart); false for an empty id.
  bool SetPaused(const std::string& robot, const std::string& by);
  bool Paused(const std::string& robot) const;
  // Takes a robot that is not connected off the floor (an operator cleared it, issue 18 §4):
  // it is no obstacle any more and releases what it held, until it connects again (Connect
  // places it where it then stands). Its plan stays (the owner changes it). False when the robot is unknown,
  // connected or in a formation team (its team's agent stands for it).
  bool Remove(const std::string& robot);
  // What happened to formations since the last call (formed again, broken up, members
  // leaving the drop), one line each, for the owner's log.
  std::vector<std::string> TakeNotes();
  const TrafficStats& stats() const;
  // One line on the robot's traffic state (for logs): where, route, what it waits on.
  std::string Describe(const std::string& robot) const;

 private:
  struct Impl;
  explicit TrafficGate(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace dispatch::engine
