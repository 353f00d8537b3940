// A rectangular robot footprint and its collision check against an OccupancyGrid (SPEC §3.7).
//
// The rectangle is `length` along the heading and `width` across it, centred on the pose,
// grown by `margin` on every side. A pose collides when the rectangle overlaps the interior
// of an occupied (or out-of-grid) cell: exact, by rows — for each grid row the rectangle
// spans, the x-extent of the rectangle clipped to that row's strip, and a per-row prefix sum
// of occupied cells says in O(1) whether any lies in it (about ten rows for a 0.8 m robot on
// 0.1 m cells). Touching a cell's edge is no overlap.
// Fast path: a pose whose cell's clearance exceeds the rectangle's circumradius plus two
// cells cannot collide and is accepted at once.
// The fast path needs the grid's clearance (OccupancyGrid::ComputeClearance); without it every
// pose takes the row scan. The checker holds a reference to the grid, which must outlive it
// and not change after the checker is made (the prefix sums are the checker's); it is
// immutable: safe to share between threads.
#pragma once

#include <vector>

#include "engine/motion/motion_path.h"
#include "engine/motion/occupancy_grid.h"

namespace dispatch::engine {

struct Footprint {
  double length = 0.8;  // metres, along the heading
  double width = 0.5;   // metres, across the heading
  double margin = 0.0;  // metres added on every side
};

class FootprintChecker {
 public:
  FootprintChecker(const OccupancyGrid& grid, const Footprint& footprint);

  bool Collides(const MotionPose& pose) const;
  // Convenience: true when any of `poses` collides.
  bool AnyCollides(const std::vector<MotionPose>& poses) const;

  const OccupancyGrid& grid() const { return grid_; }
  const Footprint& footprint() const { return footprint_; }
  double circumradius() const { return circumradius_; }

 private:
  const OccupancyGrid& grid_;
  Footprint footprint_;
  double circumradius_ = 0.0;
  double half_length_ = 0.0;
  double half_width_ = 0.0;
  std::vector<int> row_prefix_;  // row iy: occupied cells among [0, ix) at iy * (width + 1) + ix
};

}  // namespace dispatch::engine
