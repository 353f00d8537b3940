// One agent's cheapest timed path under constraints (the low level of CBS and of BIT2024's
// conflict elimination, s71/s73): A* over (vertex, step) with the steps to the goal as the
// heuristic (MapfGraph::StepsTo, admissible and consistent), waits allowed.
//
// A constraint forbids the agent a vertex at a step ("not at the conflict position at the
// conflict moment", BIT2024 s72), a move u -> v arriving at a step (a swap), a vertex from a
// step on, or bounds the step it settles at its goal (CBS's target reasoning, Li et al. 2020,
// "New techniques for pairwise symmetry breaking in multi-agent path finding"). The path ends
// at the goal at a step after the last constraint on the goal, so the agent may stay there.
// Complete: when the last constraint is at step T, a path exists iff one exists within
// T + vertices steps, and the search goes no further.
// Pure; thread-safe for distinct outputs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "engine/planning/plan_limits.h"
#include "engine/planning/timed_paths.h"

namespace dispatch::engine {

struct PathConstraint {
  enum class Kind {
    kVertex,       // not at `at` at step `time`
    kMove,         // not the move from -> at arriving at step `time`
    kAwayFrom,     // not at `at` at any step >= `time` (another agent has settled there)
    kFinishAfter,  // not settled at its goal by step `time` (its cost > time)
    kFinishBy,     // settled at its goal by step `time` (its cost <= time)
  };
  Kind kind = Kind::kVertex;
  PointId at = kNoPoint;
  PointId from = kNoPoint;  // kMove only
  int time = 0;

  static PathConstraint Vertex(PointId at, int time) { return {Kind::kVertex, at, kNoPoint, time}; }
  static PathConstraint Move(PointId from, PointId to, int time) { return {Kind::kMove, to, from, time}; }
  static PathConstraint AwayFrom(PointId at, int time) { return {Kind::kAwayFrom, at, kNoPoint, time}; }
  static PathConstraint FinishAfter(int time) { return {Kind::kFinishAfter, kNoPoint, kNoPoint, time}; }
  static PathConstraint FinishBy(int time) { return {Kind::kFinishBy, kNoPoint, kNoPoint, time}; }
};

struct AgentSearch {
  TimedPath path;
  std::size_t expanded = 0;  // states taken from the open list
};

// `steps_to_goal` = graph.StepsTo(goal). Errors: kUnreachable (no path under the
// constraints), kFailedPrecondition (stopped by `limits`).
Result<AgentSearch> PlanAgent(const MapfGraph& graph, const std::vector<int>& steps_to_goal, PointId start,
                              PointId goal, const std::vector<PathConstraint>& constraints,
                              const PlanLimits& limits = {});

}  // namespace dispatch::engine
