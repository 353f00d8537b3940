// Offline simulator (SPEC §3.8): executes the robots' timed plans (SPEC §3.4) with a fixed
// time step under the local traffic rules of Chu2024 §3.3 (traffic/), deterministically and
// as fast as the CPU allows (no clocks, no randomness).
//
// Why it is not driven by the dispatch core (engine/dispatch, issue 15): it reproduces the
// seed's own experiment (Chu2024 Fig. 8, Tables 3-4), in which timed plans made once by the
// auction are executed under the paper's offline rules (IntersectionGrants on the plan's
// times, the rear-end rule) with no dispatcher in the loop: no order stream, no re-allocation,
// no robot reports. The order-stream simulator (core_stream.h) is the one that models the
// service: it drives the dispatch core itself.
//
// Motion: each robot follows its plan's waypoint polyline in order; every segment takes its
// planned duration (eta[i+1] - departure[i], i.e. speed v or an arc's limit) while the robot
// moves, and it works `dwell` seconds at pick/drop waypoints. Formation members (Chu2024
// §3.2) drive alone to their rendezvous slot (the plan's `wait` waypoint) and wait there,
// whatever the planned wait, until all three are in place; from the next step the three move
// in lockstep as ONE agent (one shared cursor over their aligned waypoints) until the drop's
// work ends; then they split and go on alone. Robots that have finished their plans leave
// the floor (SimConfig). Alone, a robot completes exactly at its plan's times; a formation
// departs up to one step late (the rendezvous is checked once per step).
//
// Agents and reference points: a single robot (its centre) or an active formation (its
// virtual centre = the members' centroid). Groups: the members of one formation are exempt
// from each other while in formation, while gathering within TrafficConfig::gather_radius of
// their rendezvous centre, and while splitting after the drop (until each is eps1 from its
// mates; meanwhile they leave front member first: a later one yields to an earlier one).
//
// Rules on (TrafficConfig::rules_enabled), applied to agents in robot order each step:
//  - Crossing rule (eqs. (13)-(15)): for every traversal of a guard (an intersection's I_w,
//    or a merge point) the agent's path has a guarded zone from Clearance(kind) before the
//    first inner point to Clearance(kind) after the last one (capped at the first stop - a
//    pick, drop, rendezvous slot or the plan's end - after I_w). A step that would take the
//    agent's reference point into a zone it holds no grant for is not taken: the agent
//    requests the grant (IntersectionGrants: FIFO, exclusive between movements) and waits at
//    most one step's travel before the stop line. With the defaults the stop line (0.83 m
//    single, 1.06 m formation) lies before O_w (0.6 m on the Chu2024 floor), so that a crosser
//    passing the first inner point stays eps away. The grant is released when the reference
//    point has passed the zone's end (all members out of I_w).
//  - Rear-end rule (eqs. (10)-(12)): a step is not taken if it would bring the agent's
//    reference point closer than the pair's eps to another agent's reference point AND
//    closer than it was (the follower stops, the one ahead goes on). So a pair at >= eps
//    never drops below eps. Checked against the others' positions of this step so far.
// A step that is not taken still finishes any work (dwell) due in it. Waiting (grant or
// rear-end) for longer than `max_wait` simulated seconds ends the run: the agent is reported
// as blocked and every unfinished order fails with that reason.
//
// Pure function of its inputs; thread-safe.
#pragma once

#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "engine/allocation/fleet_state.h"
#include "engine/common/result.h"
#include "engine/fleet/plan.h"
#include "engine/map/warehouse_map.h"
#include "engine/traffic/safety_check.h"
#include "engine/traffic/traffic_config.h"

namespace dispatch::engine {

struct SimRobot {
  std::string id;
  Plan plan;                      // non-empty
  std::vector<QueuedTask> queue;  // one per drop waypoint of the plan, in order
};

struct SimConfig {
  double time_step = 0.1;    // s (> 0)
  double max_wait = 120.0;   // s of continuous traffic waiting before "blocked"
  double max_time = 36000;   // s: hard stop of the run
  TrafficConfig traffic;
  bool finished_robots_leave_floor = true;  // else they stay as obstacles where they ended
  bool record_frames = true;                // SimResult::frames for CheckSafety
  // The run checks itself: CheckSafety over its frames (recorded for it whatever
  // record_frames says) under `traffic`'s clearances, into SimResult::safety. On by default
  // in debug builds, the simulator's self-check of the traffic rules; release builds leave it
  // to the caller (it costs a pass over every frame).
  bool check_safety = kCheckSafetyByDefault;
};

struct OrderOutcome {
  std::string order_id;
  std::vector<std::string> robots;  // leader first
  bool completed = false;
  double completion_time = 0.0;  // when the drop's work ended (formation: the team's)
  double planned_time = 0.0;     // the plan's departure from the drop
  std::string failure;           // why it did not complete
};

struct SimResult {
  std::vector<OrderOutcome> orders;  // by first appearance in the robots' queues
  double end_time = 0.0;             // when the run stopped
  double makespan = 0.0;             // last completion time
  double total_distance = 0.0;       // m, all robots
  double total_waiting_time = 0.0;   // s, agent-seconds stopped by traffic rules
  int stops = 0;                     // times an agent moving went to a traffic stop
  std::size_t grants_issued = 0;     // intersection + merge grants
  std::size_t intersection_grants = 0;  // of which at intersections (I_w)
  std::vector<double> times;         // t of every sample (0, dt, 2 dt, ...)
  std::vector<double> min_distance;  // per sample: min robot-centre distance over pairs of
                                     // different groups (+inf with fewer than two robots)
  double overall_min_distance = std::numeric_limits<double>::infinity();
  std::vector<std::string> blocked;  // "R3 waited 120 s at t=..: ..." (deadlocks)
  std::vector<SafetyFrame> frames;   // when SimConfig::record_frames
  std::optional<SafetyReport> safety;  // when SimConfig::check_safety
  bool all_completed() const;
};

// Errors (kInvalidArgument): bad config, empty plans, duplicate ids, a queue that does not
// match its plan's drops, formation teams that name unknown robots or whose formation parts
// differ in length.
Result<SimResult> Simulate(const WarehouseMap& map, const std::vector<SimRobot>& robots,
                           const SimConfig& config = {});
// The robots of a FleetState after allocation (their plans and queues).
Result<SimResult> Simulate(const FleetState& state, const SimConfig& config = {});

}  // namespace dispatch::engine
