// dispatch-sim mapf: the discrete-time planners of engine/planning on a floor, for the record
// and for comparing them (issue 16 §2). N agents get distinct random starts and goals (seeded)
// on the floor's largest strongly connected part; the chosen planner runs under a time budget and its
// paths go through the one checker (CheckPaths). Each arc is one step: exact on grid floors
// (MovingAI maps, the generated grid floors), an approximation on maps with arcs of other
// lengths.
//   dispatch-sim mapf --map FILE.map --agents 50 [--seed 1] [--planner conflict-elimination|cbs|both]
//       [--budget-ms 10000]
// Exit status: 0 when every planner run solved and its paths passed the checker, 2 otherwise.
#pragma once

#include <cstdint>
#include <string>

namespace CLI {
class App;
}

namespace dispatch::engine {

struct MapfArgs {
  std::string map = "chu2024";
  std::size_t agents = 10;
  std::uint64_t seed = 1;
  std::string planner = "both";
  double budget_ms = 10000.0;
};

// Adds the subcommand to `app`; returns it (the caller dispatches to RunMapf when it ran).
CLI::App* AddMapfCommand(CLI::App& app, MapfArgs& args);
int RunMapf(const MapfArgs& args);

}  // namespace dispatch::engine
