// ZoneIndex: which zone of a map holds a point, in O(1) (the lookup behind the traffic-flow
// prediction, Chu2024 §2.3). Immutable once built, so predictors rebuilt every allocation
// round share one (TrafficPredictor's second constructor) instead of re-gridding the floor.
//
// Zones: ZoneAt(xy) = the lowest zone id whose Zone::Contains(xy) holds (-1 if none), answered
// through a uniform grid over the floor. A cell that lies (with a 1 mm margin) inside the
// lowest zone touching it answers directly; other cells keep the ids of the few zones touching
// them and test Contains on those in id order.
//
// Arcs: for every arc of the map the index also keeps ArcZone(arc), the one zone ZoneAt
// answers for every point of the arc's segment (within a margin far above the rounding of a
// point computed on it), or kMixedZone when that is not known to hold; route samples strictly
// on such an arc skip the grid lookup.
//
// It copies the zones it needs and keeps no reference to the map. Thread-safe (const).
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

class ZoneIndex {
 public:
  // At most this many grid cells (4 bytes each): the cell size is raised to stay below.
  static constexpr std::size_t kMaxZoneCells = std::size_t{1} << 21;
  // ArcZone's answer when ZoneAt may differ along the arc.
  static constexpr ZoneId kMixedZone = -2;

  // Builds the grid with cells of `cell_size` metres (raised for kMaxZoneCells): O(cells of
  // each zone's bounding box x its edges). Throws std::invalid_argument unless cell_size is
  // positive and finite.
  ZoneIndex(const WarehouseMap& map, double cell_size);

  // The zone holding xy (lowest id on shared borders): O(1); -1 outside every zone.
  ZoneId ZoneAt(const Eigen::Vector2d& xy) const;
  // For an arc of the map given to the constructor: z (>= -1) if ZoneAt(p) == z for every
  // point p within 1e-6 m (more for far-off coordinates) of the box spanned by the arc's end
  // points, so also for every point a + f (b - a), 0 <= f <= 1, computed in floating point;
  // kMixedZone otherwise, and for an unknown arc id. O(1).
  ZoneId ArcZone(ArcId arc) const {
    return arc >= 0 && static_cast<std::size_t>(arc) < arc_zones_.size()
               ? arc_zones_[static_cast<std::size_t>(arc)]
               : kMixedZone;
  }

  const std::vector<Zone>& zones() const { return zones_; }
  double requested_cell_size() const { return requested_cell_size_; }
  // The grid actually used (after the kMaxZoneCells cap).
  double cell_size() const { return cell_size_; }

 private:
  void BuildZoneGrid(const Eigen::Vector2d& floor_min, const Eigen::Vector2d& floor_max);
  void BuildArcZones(const WarehouseMap& map);
  // The direct answer shared by every grid cell meeting the box [lo, hi], or kMixedZone.
  ZoneId UniformZoneIn(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) const;

  double requested_cell_size_;
  std::vector<Zone> zones_;  // copies of the map's zones: polygons (Contains) and areas S_p
  // Cell (cx, cy) covers origin + [cx, cx+1] x [cy, cy+1] * cell_size_. cells_ holds a zone id
  // (answers directly), -1 (no zone) or -2 - k: test Contains on
  // candidates_[candidate_begin_[k] .. candidate_begin_[k+1]) in that (id) order.
  Eigen::Vector2d grid_origin_ = Eigen::Vector2d::Zero();
  double cell_size_ = 0.25;
  double inv_cell_size_ = 4.0;  // 1 / cell_size_
  std::int64_t grid_cols_ = 0;
  std::int64_t grid_rows_ = 0;
  std::vector<std::int32_t> cells_;
  std::vector<std::uint32_t> candidate_begin_;
  std::vector<ZoneId> candidates_;
  std::vector<ZoneId> arc_zones_;  // ArcZone per arc id
};

}  // namespace dispatch::engine
