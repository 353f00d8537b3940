// Conflict-based search (Sharon et al. 2015, "Conflict-based search for optimal multi-agent
// pathfinding"): the yardstick the seed's conflict elimination is measured against (issue
// 16 §2). A best-first search over a constraint tree: each node holds one path per agent,
// each optimal under that agent's constraints; at the node's first conflict (timed_paths.h)
// it branches in two, forbidding the conflict to one agent or the other (at an agent's goal
// after it settled there: it settles later, or everyone else keeps away from then on: target
// reasoning, Li et al. 2020, without which an agent parked at its goal costs a branch per
// step it is in the way). The first
// conflict-free node taken has the least sum of costs (ties: fewer conflicts, then the
// earlier node).
//
// Also the MapfSolution every planner of this folder returns. Deterministic; pure;
// thread-safe for distinct calls.
#pragma once

#include <cstddef>
#include <vector>

#include "engine/planning/plan_limits.h"
#include "engine/planning/timed_paths.h"

namespace dispatch::engine {

struct MapfSolution {
  std::vector<TimedPath> paths;  // one per agent, conflict-free (CheckPaths holds)
  int sum_of_costs = 0;
  std::size_t nodes = 0;     // CBS: constraint-tree nodes expanded; conflict elimination: rounds
  std::size_t searches = 0;  // single-agent searches run
};

// Errors: kInvalidArgument (CheckAgents), kUnreachable (an agent cannot reach its goal),
// kFailedPrecondition (stopped by `limits`: max_expansions counts tree nodes here).
Result<MapfSolution> SolveCbs(const MapfGraph& graph, const std::vector<MapfAgent>& agents,
                              const PlanLimits& limits = {});

}  // namespace dispatch::engine
