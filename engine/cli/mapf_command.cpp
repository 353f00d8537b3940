#include "engine/cli/mapf_command.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include "engine/io/map_source.h"
#include "engine/planning/cbs.h"
#include "engine/planning/conflict_elimination.h"

namespace dispatch::engine {
namespace {

// The largest strongly connected part among those of a few probed vertices (on a grid
// floor the first probe finds the whole floor).
std::vector<PointId> LargestPart(const MapfGraph& g) {
  std::vector<PointId> best;
  for (std::size_t probe = 0; probe < g.size() && best.size() * 2 <= g.size();
       probe += std::max<std::size_t>(1, g.size() / 8)) {
    std::vector<PointId> part = g.PartOf(static_cast<PointId>(probe));
    if (part.size() > best.size()) best = std::move(part);
  }
  return best;
}

}  // namespace

CLI::App* AddMapfCommand(CLI::App& app, MapfArgs& a) {
  auto* m = app.add_subcommand("mapf", "Discrete-time planners (BIT2024 conflict elimination, CBS) on a floor");
  m->add_option("--map", a.map, "chu2024, a JSON map file or a MovingAI .map")->capture_default_str();
  m->add_option("--agents", a.agents, "Agents with random distinct starts and goals")->capture_default_str();
  m->add_option("--seed", a.seed, "Seed of the starts and goals")->capture_default_str();
  m->add_option("--planner", a.planner, "conflict-elimination, cbs or both")->capture_default_str()
      ->check(CLI::IsMember({"conflict-elimination", "cbs", "both"}));
  m->add_option("--budget-ms", a.budget_ms, "Time budget per planner, ms")->capture_default_str()
      ->check(CLI::PositiveNumber);
  return m;
}

int RunMapf(const MapfArgs& a) {
  auto loaded = LoadMapSource(a.map);
  if (!loaded.ok()) {
    std::fprintf(stderr, "dispatch-sim: %s\n", loaded.error().message.c_str());
    return 1;
  }
  const MapfGraph graph = MapfGraph::FromMap(loaded.value());
  const std::vector<PointId> cells = LargestPart(graph);
  auto drawn = RandomAgents(cells, a.agents, a.seed);
  if (!drawn.ok()) {
    std::fprintf(stderr, "dispatch-sim: %s\n", drawn.error().message.c_str());
    return 1;
  }
  const std::vector<MapfAgent>& agents = drawn.value();
  int lower_bound = 0;
  for (const MapfAgent& agent : agents) lower_bound += graph.StepsTo(agent.goal)[static_cast<std::size_t>(agent.start)];
  std::printf("%zu agents on %s (%zu points, %zu connected), seed %llu; independent shortest paths: SOC %d\n",
              a.agents, a.map.c_str(), graph.size(), cells.size(), static_cast<unsigned long long>(a.seed),
              lower_bound);
  std::printf("%-22s %8s %10s %10s %10s %10s\n", "planner", "solved", "SOC", "nodes", "searches", "ms");
  int rc = 0;
  for (const char* name : {"conflict-elimination", "cbs"}) {
    if (a.planner != "both" && a.planner != name) continue;
    const auto budget = std::chrono::duration<double, std::milli>(a.budget_ms);
    const auto stop = DeadlineCheck(std::chrono::duration_cast<std::chrono::steady_clock::duration>(budget));
    const auto t0 = std::chrono::steady_clock::now();
    Result<MapfSolution> solved = MapfSolution{};
    if (std::string(name) == "cbs") {
      PlanLimits limits;
      limits.stop = stop;
      solved = SolveCbs(graph, agents, limits);
    } else {
      ConflictEliminationOptions options;
      options.seed = a.seed;
      options.limits.stop = stop;
      solved = EliminateConflicts(graph, agents, options);
    }
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (!solved.ok()) {
      std::printf("%-22s %8s %10s %10s %10s %10.1f  %s\n", name, "no", "-", "-", "-", ms, solved.error().message.c_str());
      rc = 2;
      continue;
    }
    const Status checked = CheckPaths(graph, agents, solved.value().paths);
    std::printf("%-22s %8s %10d %10zu %10zu %10.1f%s\n", name, checked.ok() ? "yes" : "INVALID",
                solved.value().sum_of_costs, solved.value().nodes, solved.value().searches, ms,
                checked.ok() ? "" : ("  " + checked.error().message).c_str());
    if (!checked.ok()) rc = 2;
  }
  return rc;
}

}  // namespace dispatch::engine
