// dispatch-sim motion: BIT2024 step 6's hybrid A* for four-wheel-steer (4WIS) robots beside
// the baseline (no crab, no spin: issue 17 §2) on the built-in narrow floor
// (engine/motion/narrow_floor.md), for the record (issue 17 §3). Runs the floor's queries (crab
// slot, dead end, cross floor), or one --from/--to query, with both planners under a time
// budget, prints one table (query, planner, solved or why not, length m, time s at the
// default MotionTiming, mode switches, expansions, ms; every path found goes through
// CheckMotionPath) and with --svg writes the grid, the paths and footprints every 0.5 m
// (engine/io/motion_svg.h).
// With --robots N it runs BIT2024 step 7 instead (engine/motion/motion_conflict_elimination.h):
// N robots on distinct stations of the floor (seeded draw of starts and goals among 12 fixed
// poses in the hall, the corridor's ends, the crab slot, the opening and the dead end), prints
// each robot's wait, length and arrival and the rounds, and --svg draws their paths.
//   dispatch-sim motion [--from X,Y,THETA --to X,Y,THETA] [--svg FILE] [--budget-ms 10000]
//   dispatch-sim motion --robots N [--seed 1] [--trace] [--svg FILE] [--budget-ms 10000]
// Exit status: 0 when it ran (an unsolved query is a result; with --robots: solved), 1 on bad
// arguments or an unwritable SVG file, 2 when a returned path failed the checker (with
// --robots: not solved).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace CLI {
class App;
}

namespace dispatch::engine {

struct MotionArgs {
  std::string from;  // "x,y,theta" (metres, radians); with `to`, replaces the floor's queries
  std::string to;
  std::string svg;
  double budget_ms = 10000.0;
  std::size_t robots = 0;  // > 0: step 7 for this many robots instead of the queries
  std::uint64_t seed = 1;
  bool trace = false;  // with --robots: one line per round of step 7
};

// Adds the subcommand to `app`; returns it (the caller dispatches to RunMotion when it ran).
CLI::App* AddMotionCommand(CLI::App& app, MotionArgs& args);
int RunMotion(const MotionArgs& args);

}  // namespace dispatch::engine
