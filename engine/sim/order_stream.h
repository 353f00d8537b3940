// Order-stream simulation (SPEC §3.8, issue 4 §1): robots serve a stream of orders with
// release times on a map, under the online TrafficController (engine/traffic/), with a fixed
// time step, deterministically and as fast as the CPU allows.
//
// Loop per step t (dt = time_step):
//  1. Orders whose release time (Order::release_time, else created_time) is <= t are
//     allocated together, in (priority, created, id) order, by the chosen strategy (auction
//     with zeta, or greedy nearest-idle) against the robots' CURRENT state: a FleetState is
//     rebuilt from where each robot stands (or the point it drives to, ready when it gets
//     there and has finished its work) with its unfinished tasks (remaining picks + drop)
//     re-queued, so bids see real positions, real queues and the predicted traffic.
//  2. Every robot moves: it works t_w at each pick and at the drop (Chu2024 eq. (3)), drives
//     the route table's route between stops at speed v (an arc's limit caps it) under the
//     controller (waiting, re-planning or reported blocked as the controller decides); an
//     idle robot drives home (its start point) when `return_home` and home is a station
//     (park/charge point); idle robots elsewhere stay put and are nudged when in the way.
//  3. The controller resolves wait-for cycles; the minimum pairwise robot distance is
//     sampled with a spatial hash (pairs farther apart than `distance_cap` are not measured).
// A blocked robot (TrafficController::kBlocked) leaves the floor as faulted; its orders fail
// with the controller's reason. Orders the strategy cannot allocate fail with its error.
//
// Formation orders (Chu2024 §3.2, issue 4 §3; order_stream_teams.cpp, the model of
// TrafficGate's teams): the strategy awards three robots. Once all three have the order first
// in their queues each leaves for the first pick P so as to arrive with the slowest (until
// then it waits like an idle robot); the first to stand on P hands it to the team's agent (one
// controller agent with the formation's envelope D_f: eps2 to singles, eps3 to formations) and
// the others join from the point before P, each driving into its slot of the triangle (eq. (9)).
// Then the agent serves the order like one robot, every grant and point held for the whole
// formation, the members rigidly in their slots (turning in place about the centre before an
// arc with a new heading), and after the drop the members go back to the controller beside the
// drop point while the agent still holds it, the last one onto the drop point itself once the
// others have driven off its slot. Members count as one agent (distance series, CheckSafety groups) from their approach
// until each is eps1 from its former mates. A formation that cannot form (a member blocked,
// its order failed) breaks up; a blocked formation's order fails and its members leave it
// where it stands, as at a drop.
//
// Cost per step: O(robots) plus allocation at release steps and Dijkstra on detours.
// Pure function of its inputs (no clocks, no randomness); thread-safe.
#pragma once

#include <cstddef>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "engine/allocation/allocation_config.h"
#include "engine/allocation/fleet_state.h"
#include "engine/common/result.h"
#include "engine/fleet/order.h"
#include "engine/map/warehouse_map.h"
#include "engine/routing/route_table.h"
#include "engine/traffic/safety_check.h"
#include "engine/traffic/traffic_controller.h"

namespace dispatch::engine {

// kPreassigned: each order goes to the robot StreamConfig::preassigned names (scenarios
// that fix who does what, e.g. Wang2019 §4.3).
enum class AllocationStrategy { kAuction, kGreedy, kPreassigned };
const char* AllocationStrategyName(AllocationStrategy strategy);

struct StreamConfig {
  double time_step = 0.1;     // s (> 0)
  double max_time = 36000.0;  // s: the run stops here; unfinished orders fail
  AllocationStrategy strategy = AllocationStrategy::kAuction;
  AllocationConfig allocation;          // zeta, alpha, beta, speed v, ...
  TrafficControllerConfig traffic;      // speed is taken from allocation.speed
  std::vector<std::pair<std::string, std::string>> preassigned;  // (order id, robot id)
  bool return_home = true;              // idle robots drive back to their station
  bool idle_step_aside = true;          // idle robots elsewhere leave service points/corridors
  // 0: allocate in the step an order is released (the rule). > 0: allocate released
  // orders every allocation_period seconds (a batching dispatcher; one FleetState rebuild
  // per batch - used by the large-fleet benchmark).
  double allocation_period = 0.0;
  bool record_series = true;            // times / min_distance per step
  double distance_cap = 2.0;            // m: spatial-hash cell; farther pairs not measured
  // The run checks itself (as the plan simulator does, simulator.h): every step's robot
  // positions go through CheckSafety with eps1 = traffic.point_clearance (eps2, eps3 add the
  // formation's D_f), into StreamResult::safety. On by default in debug builds; it keeps every
  // step's positions, so long release-build runs leave it off.
  bool check_safety = kCheckSafetyByDefault;
  // Every step's robot positions (with their agents and groups) in StreamResult::frames.
  bool record_frames = false;
  // SimulateOnCore: CoreOptions::one_formation_per_pick (the stream model ignores it).
  bool one_formation_per_pick = false;
  // SimulateOnCore: CoreOptions::blocked_recovery (the stream model takes a blocked robot off
  // the floor for good).
  double blocked_recovery = 60.0;
  // SimulateOnCore: for these robots, every step in [trace_from, trace_to] one line each in
  // StreamResult::trace (true position, motion state, the gate's view), and the gate's notes
  // (formations formed, broken up, leaving) of those steps: for debugging traffic.
  std::vector<std::string> trace_robots;
  double trace_from = 0.0;
  double trace_to = std::numeric_limits<double>::infinity();
};

struct StreamOrderOutcome {
  std::string order_id;
  std::string robot;              // the robot (a formation's leader)
  std::vector<std::string> team;  // a formation's three members, leader first
  double release_time = 0.0;
  double completion_time = 0.0;  // end of the drop's work
  bool completed = false;
  std::string failure;
  bool open_at_limit = false;  // failed only because the run stopped at max_time, still open
};

struct StreamResult {
  std::vector<StreamOrderOutcome> orders;  // input order
  std::size_t completed = 0;
  double end_time = 0.0;
  double makespan = 0.0;              // last completion time
  double throughput_per_hour = 0.0;   // completed / makespan * 3600
  double mean_completion = 0.0;       // mean (completion - release) over completed orders
  double total_distance = 0.0;        // m
  double total_waiting_time = 0.0;    // robot-seconds stopped by the controller
  std::size_t stops = 0;              // moving -> traffic wait transitions
  // SimulateOnCore: wall seconds spent in allocation rounds (the auction and the planner,
  // RoundRunner::Run) and the awards they made; a measurement only, no decision reads it.
  double planning_seconds = 0.0;
  std::size_t planned_awards = 0;
  TrafficStats traffic;               // re-plans, grants, deadlocks resolved, head-on log
  std::vector<std::string> blocked;   // "R3: blocked after ..." for robots taken off
  // SimulateOnCore: "R3 at 245.0 s" for each blocked robot back in service
  // (StreamConfig::blocked_recovery).
  std::vector<std::string> recovered;
  // SimulateOnCore: each time the closest pair came nearer than eps1, the two robots' traffic
  // state then (as the service logs it).
  std::vector<std::string> too_close;
  std::vector<std::string> trace;  // SimulateOnCore, StreamConfig::trace_robots
  std::vector<double> times;          // per step (record_series)
  std::vector<double> min_distance;   // per step, +inf when no pair within distance_cap
  double overall_min_distance = std::numeric_limits<double>::infinity();
  std::string min_pair;       // "R3 R7" at overall_min_distance (SimulateOnCore)
  double min_time = 0.0;      // when (SimulateOnCore)
  std::size_t steps = 0;
  std::optional<SafetyReport> safety;  // when StreamConfig::check_safety
  std::vector<SafetyFrame> frames;     // when StreamConfig::record_frames
  bool all_completed() const { return completed == orders.size(); }
};

// Errors: bad config, null map/routes, no robots, a formation order with fewer than 3 robots
// on the floor, robots that cannot be placed (unknown or shared start points).
Result<StreamResult> SimulateOrderStream(std::shared_ptr<const WarehouseMap> map,
                                         std::shared_ptr<const RouteTable> routes,
                                         const std::vector<FleetRobot>& robots,
                                         std::vector<Order> orders,
                                         const StreamConfig& config = {});

}  // namespace dispatch::engine
