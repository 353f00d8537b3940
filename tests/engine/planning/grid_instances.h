// Small grid instances for the planning tests: a 4-connected grid graph with blocked cells,
// random agents on it, and a brute-force optimum (joint-state Dijkstra) to hold CBS to.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <queue>
#include <random>
#include <string>
#include <unordered_map>
#include <vector>

#include "engine/planning/mapf_graph.h"
#include "engine/planning/timed_paths.h"

namespace dispatch::engine::testing_grid {

// rows of '.' (free) and '@' (blocked); vertex = row * width + column.
inline MapfGraph Grid(const std::vector<std::string>& rows) {
  const int h = static_cast<int>(rows.size()), w = static_cast<int>(rows.front().size());
  std::vector<std::vector<PointId>> adjacency(static_cast<std::size_t>(w * h));
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < w; ++c) {
      if (rows[r][c] != '.') continue;
      const int dr[] = {-1, 1, 0, 0}, dc[] = {0, 0, -1, 1};
      for (int k = 0; k < 4; ++k) {
        const int r2 = r + dr[k], c2 = c + dc[k];
        if (r2 < 0 || r2 >= h || c2 < 0 || c2 >= w || rows[r2][c2] != '.') continue;
        adjacency[static_cast<std::size_t>(r * w + c)].push_back(r2 * w + c2);
      }
    }
  }
  return MapfGraph::FromAdjacency(adjacency).value();
}

inline PointId Cell(const std::vector<std::string>& rows, int r, int c) {
  return r * static_cast<int>(rows.front().size()) + c;
}

struct Instance {
  std::vector<std::string> rows;
  std::vector<MapfAgent> agents;
};

// A width x height grid with each cell blocked with probability `blocked` and `agents` agents
// on distinct free start and goal cells (a goal may be another's start).
inline Instance RandomInstance(std::mt19937_64& random, int width, int height, double blocked, int agents) {
  Instance in;
  std::vector<PointId> free;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  in.rows.assign(static_cast<std::size_t>(height), std::string(static_cast<std::size_t>(width), '.'));
  for (int r = 0; r < height; ++r) {
    for (int c = 0; c < width; ++c) {
      if (u(random) < blocked) {
        in.rows[r][c] = '@';
      } else {
        free.push_back(r * width + c);
      }
    }
  }
  if (static_cast<int>(free.size()) < agents) return in;  // too few cells: no agents
  std::vector<PointId> starts = free, goals = free;
  std::shuffle(starts.begin(), starts.end(), random);
  std::shuffle(goals.begin(), goals.end(), random);
  for (int i = 0; i < agents; ++i) in.agents.push_back({starts[i], goals[i]});
  return in;
}

// The least sum of costs of conflict-free paths (timed_paths.h's rules), by Dijkstra over
// joint states (every agent's vertex, and which agents have settled at their goal for good:
// a settled agent stays; each step costs one per unsettled agent, so an agent costs the step
// it settles). None when no solution exists. For a few agents on a tiny graph only.
inline std::optional<int> BruteForceSumOfCosts(const MapfGraph& graph, const std::vector<MapfAgent>& agents) {
  const std::size_t k = agents.size();
  const auto v = static_cast<std::uint64_t>(graph.size());
  struct Joint {
    std::vector<PointId> at;
    std::uint32_t settled;
  };
  auto encode = [&](const Joint& j) {
    std::uint64_t key = j.settled;
    for (PointId p : j.at) key = key * v + static_cast<std::uint64_t>(p);
    return key;
  };
  const std::uint32_t all = (1u << k) - 1u;
  std::unordered_map<std::uint64_t, int> best;
  using Entry = std::pair<int, std::uint64_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> open;
  std::unordered_map<std::uint64_t, Joint> joints;
  auto push = [&](const Joint& j, int cost) {
    const std::uint64_t key = encode(j);
    auto it = best.find(key);
    if (it != best.end() && it->second <= cost) return;
    best[key] = cost;
    joints[key] = j;
    open.push({cost, key});
  };
  Joint start{{}, 0};
  for (const MapfAgent& a : agents) start.at.push_back(a.start);
  push(start, 0);
  while (!open.empty()) {
    const auto [cost, key] = open.top();
    open.pop();
    if (best[key] < cost) continue;
    const Joint j = joints[key];
    if (j.settled == all) return cost;
    for (std::size_t i = 0; i < k; ++i) {  // settling is free
      if (!(j.settled >> i & 1u) && j.at[i] == agents[i].goal) push({j.at, j.settled | (1u << i)}, cost);
    }
    const int step_cost = static_cast<int>(k) - __builtin_popcount(j.settled);
    // Every combination of moves of the unsettled agents.
    std::vector<std::vector<PointId>> options(k);
    for (std::size_t i = 0; i < k; ++i) {
      options[i].push_back(j.at[i]);
      if (j.settled >> i & 1u) continue;
      for (const PointId* n = graph.Neighbours(j.at[i]); n != graph.NeighboursEnd(j.at[i]); ++n) {
        options[i].push_back(*n);
      }
    }
    std::vector<PointId> next(k);
    std::function<void(std::size_t)> choose = [&](std::size_t i) {
      if (i == k) {
        for (std::size_t a = 0; a < k; ++a) {
          for (std::size_t b = a + 1; b < k; ++b) {
            if (next[a] == next[b]) return;
            if (next[a] == j.at[b] && next[b] == j.at[a]) return;  // swap
          }
        }
        push({next, j.settled}, cost + step_cost);
        return;
      }
      for (PointId p : options[i]) {
        next[i] = p;
        choose(i + 1);
      }
    };
    choose(0);
  }
  return std::nullopt;
}

}  // namespace dispatch::engine::testing_grid
