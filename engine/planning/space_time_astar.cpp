#include "engine/planning/space_time_astar.h"

#include <algorithm>
#include <limits>
#include <queue>
#include <string>
#include <tuple>
#include <unordered_set>
#include <utility>

namespace dispatch::engine {
namespace {

struct State {
  PointId v;
  int t;
  int parent;    // index into the state list, -1 for the start
  bool settles;  // at the goal, come from elsewhere (or starting there): it may stay from here
};

}  // namespace

Result<AgentSearch> PlanAgent(const MapfGraph& graph, const std::vector<int>& steps_to_goal, PointId start,
                              PointId goal, const std::vector<PathConstraint>& constraints,
                              const PlanLimits& limits) {
  if (!graph.Contains(start) || !graph.Contains(goal)) {
    return InvalidArgument("plan agent: start " + std::to_string(start) + " or goal " + std::to_string(goal) +
                           " is no vertex");
  }
  if (steps_to_goal.size() != graph.size()) return InvalidArgument("plan agent: steps_to_goal is for another graph");
  const auto vertices = static_cast<std::uint64_t>(graph.size());
  auto vertex_key = [&](PointId v, int t) { return static_cast<std::uint64_t>(t) * vertices + static_cast<std::uint64_t>(v); };
  auto move_key = [&](PointId from, PointId to, int t) {
    return (static_cast<std::uint64_t>(t) * vertices + static_cast<std::uint64_t>(from)) * vertices +
           static_cast<std::uint64_t>(to);
  };
  std::unordered_set<std::uint64_t> banned_at, banned_move;
  std::vector<std::pair<PointId, int>> away;  // (vertex, from step)
  int last_ban = 0, goal_free_after = -1;     // the agent may stay at the goal from goal_free_after + 1 on
  int finish_by = std::numeric_limits<int>::max();
  using Kind = PathConstraint::Kind;
  for (const PathConstraint& c : constraints) {
    if (c.time < 0) continue;  // can never bind
    if (c.kind == Kind::kFinishAfter) {
      goal_free_after = std::max(goal_free_after, c.time);
      last_ban = std::max(last_ban, c.time);
      continue;
    }
    if (c.kind == Kind::kFinishBy) {
      finish_by = std::min(finish_by, c.time);
      continue;
    }
    if (!graph.Contains(c.at)) continue;
    last_ban = std::max(last_ban, c.time);
    if (c.kind == Kind::kVertex) {
      banned_at.insert(vertex_key(c.at, c.time));
      if (c.at == goal) goal_free_after = std::max(goal_free_after, c.time);
    } else if (c.kind == Kind::kAwayFrom) {
      if (c.at == goal) return Unreachable("plan agent: banned from its own goal from step " + std::to_string(c.time));
      away.emplace_back(c.at, c.time);
    } else if (graph.Contains(c.from)) {
      banned_move.insert(move_key(c.from, c.at, c.time));
    }
  }
  auto kept_away = [&](PointId v, int t) {
    for (const auto& [at, from] : away) {
      if (v == at && t >= from) return true;
    }
    return false;
  };
  if (steps_to_goal[static_cast<std::size_t>(start)] == MapfGraph::kUnreachable) {
    return Unreachable("plan agent: no way from " + std::to_string(start) + " to " + std::to_string(goal));
  }
  if (banned_at.count(vertex_key(start, 0)) || kept_away(start, 0)) {
    return Unreachable("plan agent: its start " + std::to_string(start) + " is banned at step 0");
  }
  const int horizon = static_cast<int>(
      std::min<long long>(finish_by, static_cast<long long>(last_ban) + static_cast<long long>(graph.size()) + 1));
  // At the goal having waited there, it settles only by leaving and coming back: 2 steps.
  auto f_of = [&](PointId v, int t, bool settles) {
    const int h = v == goal && !settles ? 2 : steps_to_goal[static_cast<std::size_t>(v)];
    return t + std::max(h, goal_free_after + 1 - t);
  };
  // Every route to (v, t) costs t, so the first one found is as good as any: a state is
  // settled when it is first generated. At the goal, arriving there and having waited there
  // are two states: the agent's cost is the step it last arrives (PathCost), so only an
  // arrival ends the path (else a wait at the goal would hide an earlier arrival from
  // FinishAfter).
  std::vector<State> states;
  std::unordered_set<std::uint64_t> generated;
  using Entry = std::tuple<int, int, int>;  // f, -t (deeper first), state index (first generated first)
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> open;
  auto push = [&](PointId v, int t, int parent, bool settles) {
    if (!generated.insert(vertex_key(v, t) * 2 + (settles ? 1 : 0)).second) return;
    states.push_back({v, t, parent, settles});
    open.push({f_of(v, t, settles), -t, static_cast<int>(states.size()) - 1});
  };
  push(start, 0, -1, start == goal);
  AgentSearch out;
  while (!open.empty()) {
    const int index = std::get<2>(open.top());
    open.pop();
    const State s = states[static_cast<std::size_t>(index)];
    if (s.settles && s.t > goal_free_after) {
      for (int k = index; k >= 0; k = states[static_cast<std::size_t>(k)].parent) {
        out.path.push_back(states[static_cast<std::size_t>(k)].v);
      }
      std::reverse(out.path.begin(), out.path.end());
      return out;
    }
    ++out.expanded;
    if ((limits.max_expansions > 0 && out.expanded >= limits.max_expansions) ||
        ((out.expanded & 255u) == 0 && limits.stop && limits.stop())) {
      return Error{ErrorCode::kFailedPrecondition,
                   "plan agent: stopped after " + std::to_string(out.expanded) + " expansions"};
    }
    const int t = s.t + 1;
    if (t > horizon) continue;
    auto step = [&](PointId w) {
      if (steps_to_goal[static_cast<std::size_t>(w)] == MapfGraph::kUnreachable) return;
      if (banned_at.count(vertex_key(w, t)) || kept_away(w, t)) return;
      // Settled at the goal by finish_by: no later than the steps left to it.
      if (t + steps_to_goal[static_cast<std::size_t>(w)] > finish_by) return;
      if (w != s.v && banned_move.count(move_key(s.v, w, t))) return;
      push(w, t, index, w == goal && w != s.v);
    };
    step(s.v);  // wait
    for (const PointId* w = graph.Neighbours(s.v); w != graph.NeighboursEnd(s.v); ++w) step(*w);
  }
  return Unreachable("plan agent: no path from " + std::to_string(start) + " to " + std::to_string(goal) +
                     " under " + std::to_string(constraints.size()) + " constraints");
}

}  // namespace dispatch::engine
