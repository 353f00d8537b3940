// dispatch-sim routing: seed 004 §4.1-4.2, the traditional against the improved Dijkstra (path
// heat and turning time) on the 40 x 30 grid floor, run on the dispatch core
// (sim/routing_comparison.h). Per task count one row: the mean per robot over the seeds of
// distance and running time for each method, and the totals' differences.
//   dispatch-sim routing [--tasks 4,8,12,16,20] [--seeds 5] [--turn-time 1]
// Exit status: 0 when every run completed all its orders, 2 otherwise.
#pragma once

#include <cstddef>
#include <vector>

namespace CLI {
class App;
}

namespace dispatch::engine {

struct RoutingArgs {
  std::vector<std::size_t> tasks{4, 8, 12, 16, 20};
  std::size_t seeds = 5;  // seeds 1..seeds per task count
  double turn_time = 1.0;
};

// Adds the subcommand to `app`; returns it (the caller dispatches to RunRouting when it ran).
CLI::App* AddRoutingCommand(CLI::App& app, RoutingArgs& args);
int RunRouting(const RoutingArgs& args);

}  // namespace dispatch::engine
