// BIT2024 step 7 (seed 003, lines 96-103, claim 7) over the 4WIS hybrid A* of step 6: s71
// every robot's path is planned alone (PlanHybridAStar) and timed (motion_conflicts.h); s72
// the timed paths are checked for two footprints overlapping at the same sampled moment
// (FirstMotionConflict); at the first conflict one of the two robots keeps its path (chosen at
// random, seeded, as engine/planning/conflict_elimination.h does, but once per pair: when the
// same two meet again the same one keeps its path, else they could take turns waiting) and
// the other gets a position constraint; s73 that robot is re-planned under its constraints, and s72-s73 repeat
// until no conflict is left, or the limits stop it.
//
// The constraint, and how the re-plan honours it. Step 6's planner searches (x, y, theta), not
// time, so a "not here at that moment" constraint is honoured in one of two sound ways:
//  1. Detour (spatial): the constraint is the set of grid cells the kept robot's footprint
//     (grown by the clearance) covers at the sampled moments within `constraint_window`
//     seconds of the conflict. The constrained robot is re-planned on the grid with all its
//     detour cells so far marked occupied, i.e. it avoids them at every moment (stronger than
//     the seed's "at that moment": sound, not complete). Cells under the robot's own start or
//     goal footprint are left out (it cannot avoid standing there). Taken only when it adds
//     cells and the re-plan succeeds within `replan_expansions`.
//  2. Delay (temporal): otherwise the robot keeps its path and waits `delay_step` seconds
//     longer at its start; its start time is the total delay.
// Each robot gets at most `max_detours` failed detour attempts, after which it only waits.
// Exception to the kept robot's draw: waiting longer gives way to nobody when the robot to
// wait is still waiting at its start at the conflict, or the kept robot is parked at its goal
// then; in those cases the kept robot is constrained that round instead (it detours round
// the standing robot, or waits so that it arrives after it has gone / it has passed), unless
// it is itself still waiting at its start.
// Termination: every round changes one robot's (detour cells, delay) strictly — the cell set
// grows within the finite grid, or the delay grows by delay_step — and a delay past
// `max_delay` is an error, so the loop ends by itself; the limits bound it further.
// What it cannot solve: a robot that must give way part-way along its path (two robots
// head-on in a corridor where they could pass only by both keeping to the walls, or by one
// pulling into a side slot, waiting and coming out again) — waiting happens only at the
// start, the detour avoids the kept robot's cells wherever that robot runs, and it never
// reaches a pose that is not on the way to its own goal. That case ends in kUnreachable.
// Deterministic for a seed (max_expansions-bounded searches); pure; thread-safe for distinct
// calls.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "engine/common/result.h"
#include "engine/motion/footprint.h"
#include "engine/motion/hybrid_astar.h"
#include "engine/motion/motion_conflicts.h"
#include "engine/motion/occupancy_grid.h"
#include "engine/planning/plan_limits.h"

namespace dispatch::engine {

struct MotionRobot {
  MotionPose start;
  MotionPose goal;
  Footprint footprint;
};

struct MotionConflictEliminationOptions {
  std::uint64_t seed = 1;
  HybridAStarOptions planner;  // its limits are replaced: see replan_expansions and limits
  MotionTiming timing;
  MotionConflictOptions conflicts;
  double constraint_window = 1.0;   // seconds either side of the conflict
  double delay_step = 0.5;          // seconds
  double max_delay = 60.0;          // seconds
  int max_detours = 3;              // failed detour attempts per robot before it only waits
  std::size_t replan_expansions = 20000;  // per re-plan (and per first plan: 0 = unbounded)
  // max_expansions counts rounds (conflicts handled); stop is the deadline / cancel, polled
  // each round and inside every search.
  PlanLimits limits{{}, 100000};
  // Called after each round with the conflict, the constrained robot and whether it detoured
  // (else it waited); for traces. May be empty.
  std::function<void(const MotionConflict&, int constrained, bool detoured)> on_round;
};

struct MotionFleetSolution {
  std::vector<TimedMotionPath> paths;  // per robot, start_time = its delay
  std::size_t rounds = 0;              // conflicts handled
  std::size_t searches = 0;            // hybrid A* runs
  std::size_t detours = 0;             // accepted detour re-plans
  std::size_t delays = 0;              // delay steps given
};

// Errors: kInvalidArgument (no robots, bad options, a start or goal pose collides with the
// grid), kUnreachable (a robot cannot reach its goal alone, or cannot be delayed further),
// kFailedPrecondition (stopped by the limits). Every returned solution has passed
// CheckTimedMotionPaths.
Result<MotionFleetSolution> EliminateMotionConflicts(const OccupancyGrid& grid, const std::vector<MotionRobot>& robots,
                                                     const MotionConflictEliminationOptions& options = {});

}  // namespace dispatch::engine
