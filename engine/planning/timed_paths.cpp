#include "engine/planning/timed_paths.h"

#include <algorithm>
#include <functional>
#include <random>

namespace dispatch::engine {
namespace {

std::size_t Horizon(const std::vector<TimedPath>& paths) {
  std::size_t steps = 0;
  for (const TimedPath& p : paths) steps = std::max(steps, p.size());
  return steps;
}

// Calls `found` for every conflict in step order (vertex conflicts, then swaps, at each step)
// until it returns false.
void ScanConflicts(const std::vector<TimedPath>& paths, std::size_t vertices,
                   const std::function<bool(const PathConflict&)>& found) {
  const std::size_t steps = Horizon(paths);
  // occupant[v] = {step, agent}: who stands at v at that step (the first one scanned).
  std::vector<std::pair<int, int>> now(vertices, {-1, -1}), before(vertices, {-1, -1});
  for (std::size_t s = 0; s < steps; ++s) {
    const int t = static_cast<int>(s);
    for (std::size_t a = 0; a < paths.size(); ++a) {
      if (paths[a].empty()) continue;
      const PointId v = PositionAt(paths[a], t);
      auto& cell = now[static_cast<std::size_t>(v)];
      if (cell.first == t) {
        PathConflict c;
        c.kind = PathConflict::Kind::kVertex;
        c.a = cell.second;
        c.b = static_cast<int>(a);
        c.time = t;
        c.at = v;
        if (!found(c)) return;
      } else {
        cell = {t, static_cast<int>(a)};
      }
    }
    if (t > 0) {
      for (std::size_t a = 0; a < paths.size(); ++a) {
        if (paths[a].empty()) continue;
        const PointId u = PositionAt(paths[a], t - 1), v = PositionAt(paths[a], t);
        if (u == v) continue;
        const auto& cell = before[static_cast<std::size_t>(v)];
        if (cell.first != t - 1) continue;
        const int b = cell.second;
        if (b <= static_cast<int>(a) || PositionAt(paths[static_cast<std::size_t>(b)], t) != u) continue;
        PathConflict c;
        c.kind = PathConflict::Kind::kSwap;
        c.a = static_cast<int>(a);
        c.b = b;
        c.time = t;
        c.at = v;
        c.from = u;
        if (!found(c)) return;
      }
    }
    std::swap(now, before);
  }
}

}  // namespace

int PathCost(const TimedPath& path) {
  if (path.empty()) return 0;
  std::size_t last = path.size() - 1;
  while (last > 0 && path[last - 1] == path.back()) --last;
  return static_cast<int>(last);
}

int SumOfCosts(const std::vector<TimedPath>& paths) {
  int sum = 0;
  for (const TimedPath& p : paths) sum += PathCost(p);
  return sum;
}

std::optional<PathConflict> FirstConflict(const std::vector<TimedPath>& paths, std::size_t vertices) {
  std::optional<PathConflict> first;
  ScanConflicts(paths, vertices, [&](const PathConflict& c) {
    first = c;
    return false;
  });
  return first;
}

int CountConflicts(const std::vector<TimedPath>& paths, std::size_t vertices) {
  int count = 0;
  ScanConflicts(paths, vertices, [&](const PathConflict&) {
    ++count;
    return true;
  });
  return count;
}

Status CheckAgents(const MapfGraph& graph, const std::vector<MapfAgent>& agents) {
  std::vector<int> start_of(graph.size(), -1), goal_of(graph.size(), -1);
  for (std::size_t i = 0; i < agents.size(); ++i) {
    const MapfAgent& a = agents[i];
    const std::string who = "agent " + std::to_string(i);
    if (!graph.Contains(a.start)) return InvalidArgument(who + ": start " + std::to_string(a.start) + " is no vertex");
    if (!graph.Contains(a.goal)) return InvalidArgument(who + ": goal " + std::to_string(a.goal) + " is no vertex");
    int& s = start_of[static_cast<std::size_t>(a.start)];
    if (s >= 0) return InvalidArgument(who + " starts where agent " + std::to_string(s) + " starts");
    s = static_cast<int>(i);
    int& g = goal_of[static_cast<std::size_t>(a.goal)];
    if (g >= 0) return InvalidArgument(who + " has the goal of agent " + std::to_string(g));
    g = static_cast<int>(i);
  }
  return Ok{};
}

Status CheckPaths(const MapfGraph& graph, const std::vector<MapfAgent>& agents,
                  const std::vector<TimedPath>& paths) {
  if (paths.size() != agents.size()) {
    return InvalidArgument(std::to_string(paths.size()) + " paths for " + std::to_string(agents.size()) + " agents");
  }
  for (std::size_t i = 0; i < paths.size(); ++i) {
    const TimedPath& p = paths[i];
    const std::string who = "agent " + std::to_string(i);
    if (p.empty()) return InvalidArgument(who + " has no path");
    if (p.front() != agents[i].start) return InvalidArgument(who + " does not start at its start");
    if (p.back() != agents[i].goal) return InvalidArgument(who + " does not end at its goal");
    for (std::size_t t = 1; t < p.size(); ++t) {
      if (p[t] != p[t - 1] && !graph.Adjacent(p[t - 1], p[t])) {
        return InvalidArgument(who + " jumps from " + std::to_string(p[t - 1]) + " to " + std::to_string(p[t]) +
                               " at step " + std::to_string(t));
      }
    }
  }
  if (auto c = FirstConflict(paths, graph.size())) return InvalidArgument(Describe(*c));
  return Ok{};
}

std::string Describe(const PathConflict& c) {
  const std::string pair = "agents " + std::to_string(c.a) + " and " + std::to_string(c.b);
  if (c.kind == PathConflict::Kind::kVertex) {
    return pair + " both at vertex " + std::to_string(c.at) + " at step " + std::to_string(c.time);
  }
  return pair + " swap " + std::to_string(c.from) + " <-> " + std::to_string(c.at) + " arriving at step " +
         std::to_string(c.time);
}

Result<std::vector<MapfAgent>> RandomAgents(const std::vector<PointId>& cells, std::size_t n, std::uint64_t seed) {
  if (cells.size() < n) {
    return InvalidArgument(std::to_string(n) + " agents do not fit on " + std::to_string(cells.size()) +
                           " connected points");
  }
  std::mt19937_64 random(seed);
  std::vector<PointId> starts = cells, goals = cells;
  std::shuffle(starts.begin(), starts.end(), random);
  std::shuffle(goals.begin(), goals.end(), random);
  std::vector<MapfAgent> agents;
  for (std::size_t i = 0; i < n; ++i) agents.push_back({starts[i], goals[i]});
  return agents;
}

}  // namespace dispatch::engine
