// BIT2024 step 7 (seed 003, s71-s73): conflict-free paths by eliminating conflicts one at a
// time. s71: every robot's path is planned alone. s72: the paths are checked for the same
// position at the same moment (and, in discrete time, a swap: timed_paths.h); at the first
// conflict one of the robots there keeps its path (chosen at random, seeded) and every other
// one gets a constraint: not at that position at that moment (a swap: not that move then).
// s73: those robots are re-planned under all their constraints so far, and s72-s73 repeat
// until no conflict is left, or the limits stop it.
//
// Unlike CBS it never backtracks, so it is fast but neither optimal nor complete: the sum of
// costs is never below CBS's optimum (tests check it) and it may stop without a solution.
// Deterministic for a seed; pure; thread-safe for distinct calls.
#pragma once

#include <cstdint>
#include <vector>

#include "engine/planning/cbs.h"

namespace dispatch::engine {

struct ConflictEliminationOptions {
  std::uint64_t seed = 1;
  // max_expansions counts rounds (conflicts eliminated) here; the loop need not end by itself.
  PlanLimits limits{{}, 100000};
};

// Errors: kInvalidArgument (CheckAgents), kUnreachable (an agent cannot reach its goal, or
// no longer under its constraints), kFailedPrecondition (stopped by the limits).
Result<MapfSolution> EliminateConflicts(const MapfGraph& graph, const std::vector<MapfAgent>& agents,
                                        const ConflictEliminationOptions& options = {});

}  // namespace dispatch::engine
