// Lane corridors: maximal chains of bidirectional single lanes (Wang2019 §3.3; SPEC §2 "a
// bidirectional single lane, usable in one direction at a time").
//
// A corridor is a chain of single-lane paths joined at interior points: points of undirected
// degree 2 whose two paths are both single lanes (no robot can pass another or turn off
// there). Its two end points (junctions, dead ends) are not part of it. On an imported grid
// most corridors are one arc between two junction cells; in a one-cell-wide aisle a corridor
// is the whole aisle. The traffic controller reserves a corridor for one direction at a time.
//
// Invariants: every single-lane path belongs to exactly one corridor; one-way paths to none;
// corridor.points has paths + 1 entries, path k joins points[k] and points[k + 1] (a closed
// ring repeats its first point at the end). Pure function of the map; thread-safe.
#pragma once

#include <cstdint>
#include <vector>

#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

struct LaneCorridor {
  std::vector<PointId> points;        // end, interior..., end
  std::vector<std::int32_t> paths;    // map path ids, in chain order
};

struct LaneCorridors {
  std::vector<LaneCorridor> corridors;
  std::vector<int> corridor_of_path;  // per map path: corridor index or -1 (one-way)
  std::vector<int> index_in_corridor; // per map path: its k in the corridor, or -1
  std::vector<int> interior_of;       // per point: corridor whose interior it is, or -1

  // Corridor of an arc (-1 for one-way arcs).
  int CorridorOfArc(const WarehouseMap& map, ArcId arc) const {
    return corridor_of_path[static_cast<std::size_t>(map.arc(arc).path)];
  }
  // +1 when the arc runs from points.front() towards points.back(), else -1.
  int Direction(const WarehouseMap& map, ArcId arc) const;
};

LaneCorridors BuildLaneCorridors(const WarehouseMap& map);

}  // namespace dispatch::engine
