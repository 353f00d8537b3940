// Wang2019 §4.1-4.2 (seed 004): the traditional Dijkstra against the improved one (path heat,
// eqs. (13)-(14), and turning time, eq. (3)) on a 40 x 30 grid floor, run on the dispatch core
// (SimulateOnCore: the service's allocation rounds, traffic gate and controller) with robots
// that turn in place at `turn_time` seconds per 90 degrees in both runs.
//   traditional: route table (Dijkstra per destination, the lazy table) without turning time,
//                AllocationConfig::routing = floyd (the table's routes);
//   improved:    route table with turn_penalty_s = turn_time (bids and routes count turns),
//                routing = heat (each award's legs re-routed over the heat-weighted lengths
//                plus turning time, RouteAwardsByHeat / HeatRoute).
// Both know the robots' turning time in their ETAs (AllocationConfig::turn_time); only the
// route choice differs, as between the seed's two methods.
//
// Floor: BuildWang2019Floor (map/grid_floor.h), the 40 x 30 grid. The seed's task tables 1, 2
// and 5 are not in its text, so tasks here are drawn from a seed.
// Tasks: `tasks` robots (R1.. spread over the floor, sim/fleet_placement.h) and `tasks` orders
// released at 0 s, each from a random pick to a random drop (sim/random_orders.h, `seed`).
// Per method: total distance driven and total running time (sum over orders of completion -
// release, the seed's "总运行时间"), their means per robot, makespan, waiting, re-plans.
// Pure functions; thread-safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "engine/common/result.h"

namespace dispatch::engine {

struct RoutingRun {
  std::size_t completed = 0;
  double total_distance = 0.0;  // m
  double total_time = 0.0;      // s: Σ (completion - release)
  double makespan = 0.0;        // s
  double waiting = 0.0;         // robot-s stopped by the traffic gate
  std::size_t replans = 0;
  std::vector<std::string> failures;  // "O3: <why>" per order not completed
};

struct RoutingComparison {
  std::size_t tasks = 0;
  std::uint64_t seed = 0;
  RoutingRun traditional, improved;
};

struct RoutingComparisonOptions {
  std::size_t tasks = 4;   // robots = orders
  std::uint64_t seed = 1;
  double turn_time = 1.0;  // s per 90 degrees (> 0: the improved method's second term)
  double work_time = 5.0;  // s per pick and drop
};

// Errors: tasks 0 or more than the floor's lane points, turn_time < 0, a run that fails.
Result<RoutingComparison> RunRoutingComparison(const RoutingComparisonOptions& options);

}  // namespace dispatch::engine
