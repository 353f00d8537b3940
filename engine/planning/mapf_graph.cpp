#include "engine/planning/mapf_graph.h"

#include <algorithm>
#include <string>
#include <utility>

namespace dispatch::engine {
namespace {

// Compressed rows of `rows` (sorted, without duplicates and self-loops).
void Compress(std::vector<std::vector<PointId>> rows, std::vector<std::uint32_t>& begin,
              std::vector<PointId>& next) {
  begin.assign(rows.size() + 1, 0);
  next.clear();
  for (std::size_t v = 0; v < rows.size(); ++v) {
    auto& row = rows[v];
    row.erase(std::remove(row.begin(), row.end(), static_cast<PointId>(v)), row.end());
    std::sort(row.begin(), row.end());
    row.erase(std::unique(row.begin(), row.end()), row.end());
    next.insert(next.end(), row.begin(), row.end());
    begin[v + 1] = static_cast<std::uint32_t>(next.size());
  }
}

}  // namespace

MapfGraph::MapfGraph(const std::vector<std::vector<PointId>>& adjacency) {
  Compress(adjacency, begin_, next_);
  std::vector<std::vector<PointId>> reverse(adjacency.size());
  for (std::size_t u = 0; u < adjacency.size(); ++u) {
    for (PointId v : adjacency[u]) reverse[static_cast<std::size_t>(v)].push_back(static_cast<PointId>(u));
  }
  Compress(std::move(reverse), rbegin_, prev_);
}

MapfGraph MapfGraph::FromMap(const WarehouseMap& map) {
  std::vector<std::vector<PointId>> adjacency(map.point_count());
  for (const Arc& a : map.arcs()) adjacency[static_cast<std::size_t>(a.from)].push_back(a.to);
  return MapfGraph(adjacency);
}

Result<MapfGraph> MapfGraph::FromAdjacency(const std::vector<std::vector<PointId>>& adjacency) {
  for (std::size_t u = 0; u < adjacency.size(); ++u) {
    for (PointId v : adjacency[u]) {
      if (v < 0 || static_cast<std::size_t>(v) >= adjacency.size()) {
        return InvalidArgument("mapf graph: vertex " + std::to_string(u) + " has neighbour " +
                               std::to_string(v) + ", outside 0.." + std::to_string(adjacency.size()));
      }
    }
  }
  return MapfGraph(adjacency);
}

bool MapfGraph::Adjacent(PointId u, PointId v) const {
  if (!Contains(u) || !Contains(v)) return false;
  return std::binary_search(Neighbours(u), NeighboursEnd(u), v);
}

std::vector<int> MapfGraph::Levels(PointId from, const std::vector<std::uint32_t>& begin,
                                  const std::vector<PointId>& next, std::size_t size) {
  std::vector<int> steps(size, kUnreachable);
  if (from < 0 || static_cast<std::size_t>(from) >= size) return steps;
  std::vector<PointId> frontier{from};
  steps[static_cast<std::size_t>(from)] = 0;
  for (std::size_t head = 0; head < frontier.size(); ++head) {
    const auto vi = static_cast<std::size_t>(frontier[head]);
    const int d = steps[vi] + 1;
    for (std::uint32_t k = begin[vi]; k < begin[vi + 1]; ++k) {
      const auto u = static_cast<std::size_t>(next[k]);
      if (steps[u] != kUnreachable) continue;
      steps[u] = d;
      frontier.push_back(next[k]);
    }
  }
  return steps;
}

std::vector<int> MapfGraph::StepsTo(PointId goal) const { return Levels(goal, rbegin_, prev_, size()); }

std::vector<int> MapfGraph::StepsFrom(PointId source) const { return Levels(source, begin_, next_, size()); }

std::vector<PointId> MapfGraph::PartOf(PointId v) const {
  const std::vector<int> to = StepsTo(v), from = StepsFrom(v);
  std::vector<PointId> part;
  for (std::size_t u = 0; u < size(); ++u) {
    if (to[u] != kUnreachable && from[u] != kUnreachable) part.push_back(static_cast<PointId>(u));
  }
  return part;
}

}  // namespace dispatch::engine
