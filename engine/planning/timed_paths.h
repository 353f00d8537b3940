// Timed paths of agents on a MapfGraph and the one checker every planner is held to (SPEC
// §3.6; the role of lacam3's is_feasible_solution). A path lists an agent's vertex at steps
// 0, 1, 2, ...; after its last entry the agent stays there for ever (its goal).
//
// Conflicts (BIT2024 s72 "the same position at the same moment", plus the swap, which a
// discrete-time model would otherwise let two robots drive through each other on one lane):
//   vertex: two agents at one vertex at step t;
//   swap:   one agent moves u -> v and another v -> u between steps t-1 and t.
// Pure functions; thread-safe.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "engine/common/result.h"
#include "engine/planning/mapf_graph.h"

namespace dispatch::engine {

using TimedPath = std::vector<PointId>;

struct MapfAgent {
  PointId start = kNoPoint;
  PointId goal = kNoPoint;
};

struct PathConflict {
  enum class Kind { kVertex, kSwap };
  Kind kind = Kind::kVertex;
  int a = -1, b = -1;  // agents, a < b
  int time = 0;        // the step at which they collide (a swap: the step they arrive)
  PointId at = kNoPoint;  // vertex: where; swap: where a arrives (b arrives at `from`)
  PointId from = kNoPoint;  // swap: where a comes from
};

// Where an agent following `path` is at step t (its last vertex once it has arrived).
inline PointId PositionAt(const TimedPath& path, int t) {
  return path[static_cast<std::size_t>(t) < path.size() ? static_cast<std::size_t>(t) : path.size() - 1];
}

// An agent's cost: the step it arrives at its goal for the last time (trailing waits at the
// goal do not count). The sum over agents is the sum of costs (SOC) the planners minimise.
int PathCost(const TimedPath& path);
int SumOfCosts(const std::vector<TimedPath>& paths);

// The earliest conflict among `paths` (vertex conflicts before swaps at one step, lower agents
// first), or none. Empty paths are ignored. O(agents x steps).
std::optional<PathConflict> FirstConflict(const std::vector<TimedPath>& paths, std::size_t vertices);
// The number of conflicting pairs over all steps (a planner's tie-break), O(agents x steps).
int CountConflicts(const std::vector<TimedPath>& paths, std::size_t vertices);

// The checker: one non-empty path per agent, starting at its start and ending at its goal,
// each step a wait or an edge of `graph`, no conflict. Errors name the first fault.
Status CheckPaths(const MapfGraph& graph, const std::vector<MapfAgent>& agents,
                  const std::vector<TimedPath>& paths);

// Checks an instance before planning: every start and goal a vertex, starts distinct, goals
// distinct (two agents cannot both stay at one goal).
Status CheckAgents(const MapfGraph& graph, const std::vector<MapfAgent>& agents);

std::string Describe(const PathConflict& c);

// n agents with distinct starts and distinct goals drawn (seeded) from `cells`, which must be
// one strongly connected part (MapfGraph::PartOf) so every goal is reachable from every start.
// Errors: fewer cells than agents.
Result<std::vector<MapfAgent>> RandomAgents(const std::vector<PointId>& cells, std::size_t n, std::uint64_t seed);

}  // namespace dispatch::engine
