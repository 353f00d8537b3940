// The graph the conflict-free planners search (SPEC §3.6, BIT2024 step 7): the map's points
// as vertices and its arcs as directed edges, in discrete time. Each step an agent moves along
// one edge or waits where it is (unit-time moves: the grid floors, MovingAI and LoRR cells,
// where every arc is one cell long). An agent stays at its goal once it has arrived.
//
// Invariants: vertices 0 .. size()-1 (a map's PointIds); the neighbours of a vertex are
// distinct, sorted and never the vertex itself. Immutable once built; safe to share.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "engine/common/result.h"
#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

class MapfGraph {
 public:
  static constexpr int kUnreachable = std::numeric_limits<int>::max();

  // Every arc of the map is an edge (a bidirectional lane is two arcs, so two edges).
  static MapfGraph FromMap(const WarehouseMap& map);
  // adjacency[v] = the vertices one step from v. Errors: a neighbour out of range.
  static Result<MapfGraph> FromAdjacency(const std::vector<std::vector<PointId>>& adjacency);

  std::size_t size() const { return begin_.empty() ? 0 : begin_.size() - 1; }
  bool Contains(PointId v) const { return v >= 0 && static_cast<std::size_t>(v) < size(); }
  // The neighbours of v: [Neighbours(v), NeighboursEnd(v)).
  const PointId* Neighbours(PointId v) const { return next_.data() + begin_[static_cast<std::size_t>(v)]; }
  const PointId* NeighboursEnd(PointId v) const {
    return next_.data() + begin_[static_cast<std::size_t>(v) + 1];
  }
  bool Adjacent(PointId u, PointId v) const;  // one step from u to v (u != v)

  // Steps from every vertex to `goal` (kUnreachable where there is no way): the planners'
  // heuristic, exact for a free floor. Breadth-first search backwards, O(V + E).
  std::vector<int> StepsTo(PointId goal) const;
  // Steps from `source` to every vertex (kUnreachable where there is no way), forwards.
  std::vector<int> StepsFrom(PointId source) const;
  // The vertices that `v` reaches and that reach `v` (its strongly connected part), sorted.
  std::vector<PointId> PartOf(PointId v) const;

 private:
  explicit MapfGraph(const std::vector<std::vector<PointId>>& adjacency);
  static std::vector<int> Levels(PointId from, const std::vector<std::uint32_t>& begin,
                                 const std::vector<PointId>& next, std::size_t size);

  std::vector<std::uint32_t> begin_;  // CSR offsets, size() + 1
  std::vector<PointId> next_;
  std::vector<std::uint32_t> rbegin_;  // the reverse graph, for StepsTo
  std::vector<PointId> prev_;
};

}  // namespace dispatch::engine
