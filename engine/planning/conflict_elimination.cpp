#include "engine/planning/conflict_elimination.h"

#include <random>
#include <string>

#include "engine/planning/space_time_astar.h"

namespace dispatch::engine {

Result<MapfSolution> EliminateConflicts(const MapfGraph& graph, const std::vector<MapfAgent>& agents,
                                        const ConflictEliminationOptions& options) {
  if (Status ok = CheckAgents(graph, agents); !ok.ok()) return ok.error();
  PlanLimits search_limits;  // a single search is bounded by the caller's stop only
  search_limits.stop = options.limits.stop;
  std::vector<std::vector<int>> steps;
  std::vector<std::vector<PathConstraint>> constraints(agents.size());
  MapfSolution out;
  auto plan = [&](std::size_t i) -> Status {
    auto found = PlanAgent(graph, steps[i], agents[i].start, agents[i].goal, constraints[i], search_limits);
    ++out.searches;
    if (!found.ok()) {
      return Error{found.error().code, "agent " + std::to_string(i) + " (" + std::to_string(constraints[i].size()) +
                                           " constraints): " + found.error().message};
    }
    out.paths[i] = std::move(found.value().path);
    return Ok{};
  };
  // s71: each robot alone.
  out.paths.resize(agents.size());
  for (std::size_t i = 0; i < agents.size(); ++i) {
    steps.push_back(graph.StepsTo(agents[i].goal));
    if (Status ok = plan(i); !ok.ok()) return ok.error();
  }
  std::mt19937_64 random(options.seed);
  std::vector<int> involved;
  while (true) {
    // s72: the first conflict, or done.
    const auto c = FirstConflict(out.paths, graph.size());
    if (!c) break;
    ++out.nodes;
    if (options.limits.Exhausted(out.nodes)) {
      return Error{ErrorCode::kFailedPrecondition,
                   "conflict elimination: stopped after " + std::to_string(out.nodes) + " rounds at " + Describe(*c)};
    }
    involved.clear();
    if (c->kind == PathConflict::Kind::kVertex) {  // every robot at that position then
      for (std::size_t i = 0; i < out.paths.size(); ++i) {
        if (PositionAt(out.paths[i], c->time) == c->at) involved.push_back(static_cast<int>(i));
      }
    } else {
      involved = {c->a, c->b};
    }
    const int keep = involved[static_cast<std::size_t>(random() % involved.size())];
    // s73: the others get a constraint and are planned again.
    for (int i : involved) {
      if (i == keep) continue;
      PathConstraint ban = PathConstraint::Vertex(c->at, c->time);
      if (c->kind == PathConflict::Kind::kSwap) {
        ban = i == c->a ? PathConstraint::Move(c->from, c->at, c->time) : PathConstraint::Move(c->at, c->from, c->time);
      }
      constraints[static_cast<std::size_t>(i)].push_back(ban);
      if (Status ok = plan(static_cast<std::size_t>(i)); !ok.ok()) {
        return Error{ok.error().code, "conflict elimination: " + ok.error().message};
      }
    }
  }
  out.sum_of_costs = SumOfCosts(out.paths);
  return out;
}

}  // namespace dispatch::engine
