// What an order-stream run on the dispatch core (core_stream.h) is asked to do and what it
// reports: the run's settings (StreamConfig), and per order and overall its outcome
// (StreamResult). Plain values.
#pragma once

#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "engine/allocation/allocation_config.h"
#include "engine/traffic/safety_check.h"
#include "engine/traffic/traffic_controller.h"

namespace dispatch::engine {

// MakeAllocator's strategies (engine/dispatch/strategy.h), by value.
enum class AllocationStrategy { kAuction, kGreedy, kExact, kPsoGa };
const char* AllocationStrategyName(AllocationStrategy strategy);  // "auction", "greedy", "exact", "psoga"
std::optional<AllocationStrategy> ParseAllocationStrategy(std::string_view name);

struct StreamConfig {
  double time_step = 0.1;     // s (> 0)
  double max_time = 36000.0;  // s: the run stops here; unfinished orders fail
  AllocationStrategy strategy = AllocationStrategy::kAuction;
  AllocationConfig allocation;      // zeta, alpha, beta, speed v, planner, routing, queues, ...
  TrafficControllerConfig traffic;  // speed is taken from allocation.speed
  // 0: a round whenever the core says one is due (an order arrived or came back, a robot
  // finished an order or left a formation). > 0: at most every allocation_period seconds (a
  // batching dispatcher).
  double allocation_period = 0.0;
  // The run checks itself (as the plan simulator does, simulator.h): every step's true robot
  // positions go through CheckSafety with eps1 = traffic.point_clearance (eps2, eps3 add the
  // formation's D_f), into StreamResult::safety. On by default in debug builds; it keeps every
  // step's positions, so long release-build runs leave it off.
  bool check_safety = kCheckSafetyByDefault;
  // Every step's robot positions (with their agents and groups) in StreamResult::frames.
  bool record_frames = false;
  // CoreOptions::one_formation_per_pick: a formation order is allocated only while no other
  // formation is heading for its first pick (dispatchd's and dispatch-sim's default: on).
  bool one_formation_per_pick = false;
  // CoreOptions::blocked_recovery: seconds a blocked robot stays in fault before it is back in
  // service (0: never).
  double blocked_recovery = 60.0;
  // For these robots, every step in [trace_from, trace_to] one line each in
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
  double total_waiting_time = 0.0;    // robot-seconds stopped by the traffic gate
  std::size_t stops = 0;              // moving -> traffic wait transitions
  // Wall seconds spent in allocation rounds (the auction and the planner, RoundRunner::Run)
  // and the awards they made; a measurement only, no decision reads it.
  double planning_seconds = 0.0;
  std::size_t planned_awards = 0;
  TrafficStats traffic;               // re-plans, grants, deadlocks resolved, head-on log
  std::vector<std::string> blocked;   // "R3: blocked: ..." for each robot the gate blocked
  // "R3 at 245.0 s" for each blocked robot back in service (StreamConfig::blocked_recovery).
  std::vector<std::string> recovered;
  // Each time the closest pair came nearer than eps1, the two robots' traffic state then (as
  // the service logs it).
  std::vector<std::string> too_close;
  std::vector<std::string> trace;  // StreamConfig::trace_robots
  double overall_min_distance = std::numeric_limits<double>::infinity();
  std::string min_pair;  // "R3 R7" at overall_min_distance
  double min_time = 0.0;  // when
  std::size_t steps = 0;
  std::optional<SafetyReport> safety;  // when StreamConfig::check_safety
  std::vector<SafetyFrame> frames;     // when StreamConfig::record_frames
  bool all_completed() const { return completed == orders.size(); }
};

}  // namespace dispatch::engine
