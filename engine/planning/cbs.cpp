#include "engine/planning/cbs.h"

#include <memory>
#include <queue>
#include <string>
#include <tuple>

#include "engine/planning/space_time_astar.h"

namespace dispatch::engine {
namespace {

struct CtNode {
  int parent = -1;
  int agent = -1;  // the agent constrained here (-1: the root)
  PathConstraint constraint;
  std::vector<std::shared_ptr<const TimedPath>> paths;  // unchanged paths are shared
  int cost = 0;
  int conflicts = 0;
};

std::vector<TimedPath> Unshare(const std::vector<std::shared_ptr<const TimedPath>>& paths) {
  std::vector<TimedPath> out;
  out.reserve(paths.size());
  for (const auto& p : paths) out.push_back(*p);
  return out;
}

// The constraints on agent x in `leaf` (not yet in the tree; its parent is): its own, and for
// every agent that settled at its goal by a step, to keep away from that goal from then on.
std::vector<PathConstraint> ConstraintsOf(const std::vector<CtNode>& tree, const CtNode& leaf, int x,
                                          const std::vector<MapfAgent>& agents) {
  std::vector<PathConstraint> out;
  auto take = [&](const CtNode& n) {
    if (n.agent == x) {
      out.push_back(n.constraint);
    } else if (n.agent >= 0 && n.constraint.kind == PathConstraint::Kind::kFinishBy) {
      out.push_back(PathConstraint::AwayFrom(agents[static_cast<std::size_t>(n.agent)].goal, n.constraint.time));
    }
  };
  take(leaf);
  for (int k = leaf.parent; k > 0; k = tree[static_cast<std::size_t>(k)].parent) take(tree[static_cast<std::size_t>(k)]);
  return out;
}

}  // namespace

Result<MapfSolution> SolveCbs(const MapfGraph& graph, const std::vector<MapfAgent>& agents,
                              const PlanLimits& limits) {
  if (Status ok = CheckAgents(graph, agents); !ok.ok()) return ok.error();
  std::vector<std::vector<int>> steps;
  steps.reserve(agents.size());
  for (const MapfAgent& a : agents) steps.push_back(graph.StepsTo(a.goal));
  PlanLimits search_limits;  // a single search is bounded by the caller's stop only
  search_limits.stop = limits.stop;

  MapfSolution out;
  std::vector<CtNode> tree;
  CtNode root;
  for (std::size_t i = 0; i < agents.size(); ++i) {
    auto found = PlanAgent(graph, steps[i], agents[i].start, agents[i].goal, {}, search_limits);
    ++out.searches;
    if (!found.ok()) return Error{found.error().code, "agent " + std::to_string(i) + ": " + found.error().message};
    root.paths.push_back(std::make_shared<const TimedPath>(std::move(found.value().path)));
  }
  auto evaluate = [&](CtNode& n) {
    const std::vector<TimedPath> paths = Unshare(n.paths);
    n.cost = SumOfCosts(paths);
    n.conflicts = CountConflicts(paths, graph.size());
  };
  evaluate(root);
  tree.push_back(std::move(root));
  using Entry = std::tuple<int, int, int>;  // cost, conflicts, node
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> open;
  open.push({tree[0].cost, tree[0].conflicts, 0});

  while (!open.empty()) {
    const int id = std::get<2>(open.top());
    open.pop();
    std::vector<TimedPath> paths = Unshare(tree[static_cast<std::size_t>(id)].paths);
    const auto conflict = FirstConflict(paths, graph.size());
    if (!conflict) {
      out.sum_of_costs = SumOfCosts(paths);
      out.paths = std::move(paths);
      return out;
    }
    ++out.nodes;
    if (limits.Exhausted(out.nodes)) {
      return Error{ErrorCode::kFailedPrecondition, "cbs: stopped after " + std::to_string(out.nodes) +
                                                       " nodes (best bound " +
                                                       std::to_string(tree[static_cast<std::size_t>(id)].cost) + ")"};
    }
    const PathConflict& c = *conflict;
    // A target conflict (Li et al. 2020): one agent has settled at its goal and the other
    // comes by later. Split on when it settles, not on one step at a time.
    int settled = -1;
    if (c.kind == PathConflict::Kind::kVertex) {
      for (int x : {c.a, c.b}) {
        const auto xi = static_cast<std::size_t>(x);
        if (agents[xi].goal == c.at && PathCost(paths[xi]) <= c.time) settled = x;
      }
    }
    for (int side = 0; side < 2; ++side) {
      CtNode child;
      child.parent = id;
      std::vector<int> replan;
      if (settled >= 0) {
        child.agent = settled;
        if (side == 0) {  // it settles later: it is planned again
          child.constraint = PathConstraint::FinishAfter(c.time);
          replan.push_back(settled);
        } else {  // it has settled by then: everyone who comes by later is planned again
          child.constraint = PathConstraint::FinishBy(c.time);
          for (std::size_t x = 0; x < paths.size(); ++x) {
            const TimedPath& p = paths[x];
            for (std::size_t t = static_cast<std::size_t>(c.time); t < p.size(); ++t) {
              if (p[t] == c.at && static_cast<int>(x) != settled) {
                replan.push_back(static_cast<int>(x));
                break;
              }
            }
          }
        }
      } else {
        child.agent = side == 0 ? c.a : c.b;
        replan.push_back(child.agent);
        if (c.kind == PathConflict::Kind::kVertex) {
          child.constraint = PathConstraint::Vertex(c.at, c.time);
        } else {
          child.constraint = side == 0 ? PathConstraint::Move(c.from, c.at, c.time)
                                       : PathConstraint::Move(c.at, c.from, c.time);
        }
      }
      child.paths = tree[static_cast<std::size_t>(id)].paths;
      bool feasible = true;
      for (int x : replan) {
        const auto xi = static_cast<std::size_t>(x);
        const std::vector<PathConstraint> constraints = ConstraintsOf(tree, child, x, agents);
        auto found = PlanAgent(graph, steps[xi], agents[xi].start, agents[xi].goal, constraints, search_limits);
        ++out.searches;
        if (!found.ok()) {
          if (found.error().code != ErrorCode::kUnreachable) return Error{found.error().code, "cbs: " + found.error().message};
          feasible = false;  // this branch has no solution
          break;
        }
        child.paths[xi] = std::make_shared<const TimedPath>(std::move(found.value().path));
      }
      if (!feasible) continue;
      evaluate(child);
      tree.push_back(std::move(child));
      open.push({tree.back().cost, tree.back().conflicts, static_cast<int>(tree.size()) - 1});
    }
  }
  return Unreachable("cbs: no conflict-free paths exist for these agents");
}

}  // namespace dispatch::engine
