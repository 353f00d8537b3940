// A rectangular robot footprint and its collision check against an OccupancyGrid (SPEC §3.7).
//
// The rectangle is `length` along the heading and `width` across it, centred on the pose,
// grown by `margin` on every side. A pose collides when a sample point of the rectangle lies
// in an occupied (or out-of-grid) cell. The samples form a lattice with spacing at most half a
// cell over the rectangle, boundary included, so every cell the rectangle covers entirely
// holds a sample (a square of side `resolution` always contains a point of a lattice of
// spacing resolution / 2) and cells crossed by an edge are caught down to slivers of about
// a quarter cell. `margin` covers that slack when it matters.
// Fast path: a pose whose cell's clearance exceeds the rectangle's circumradius plus two
// cells cannot collide and is accepted without sampling.
// The fast path needs the grid's clearance (OccupancyGrid::ComputeClearance); without it every
// pose is sampled. The checker holds a reference to the grid, which must outlive it; it is
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
  std::vector<Eigen::Vector2d> samples_;  // in the robot frame, x along the heading
};

}  // namespace dispatch::engine
