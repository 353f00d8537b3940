// A 2-D occupancy grid for continuous-pose planning (SPEC §3.7): square cells of side
// `resolution` metres, cell (0, 0) with its lower-left corner at `origin`. Everything outside
// the grid counts as occupied, so a planner never leaves the floor.
//
// Besides occupancy it holds each cell's clearance: the distance (metres) from the cell's
// centre to the nearest occupied cell centre or the grid's edge, computed on demand by
// ComputeClearance (exact Euclidean distance to the nearest site found by a Dijkstra sweep
// that carries the site along; within a cell of the true value). The footprint check uses it
// to accept poses far from any obstacle without sampling.
// A built grid is immutable for readers: safe to share between threads once built.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <string_view>
#include <vector>

#include "engine/common/result.h"
#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

class OccupancyGrid {
 public:
  // All cells free. width, height >= 1; resolution > 0.
  OccupancyGrid(int width, int height, double resolution, Eigen::Vector2d origin = Eigen::Vector2d::Zero());

  // The map's floor rectangle with its shelves as obstacles (a cell is occupied when its
  // centre lies in a shelf, or the shelf covers part of it: shelves are rounded outwards).
  static Result<OccupancyGrid> FromMap(const WarehouseMap& map, double resolution);

  // A MovingAI `.map` text (header "type", "height H", "width W", "map", then H rows, the
  // first row the north edge): '@', 'T', 'O' and 'W' are blocked, every other character
  // free. Each map tile is `tile` metres square and becomes subdivide x subdivide cells
  // (resolution tile / subdivide); origin (0, 0), y up. kInvalidArgument on a malformed text.
  static Result<OccupancyGrid> FromMovingAi(std::string_view text, double tile, int subdivide = 1);

  int width() const { return width_; }
  int height() const { return height_; }
  double resolution() const { return resolution_; }
  const Eigen::Vector2d& origin() const { return origin_; }

  bool InBounds(int ix, int iy) const { return ix >= 0 && iy >= 0 && ix < width_ && iy < height_; }
  // Out-of-bounds cells are occupied.
  bool Occupied(int ix, int iy) const {
    return !InBounds(ix, iy) || cells_[static_cast<std::size_t>(iy) * width_ + ix] != 0;
  }
  // The cell that holds point (x, y) (may be out of bounds).
  int CellX(double x) const;
  int CellY(double y) const;
  bool OccupiedAt(double x, double y) const { return Occupied(CellX(x), CellY(y)); }

  void Set(int ix, int iy, bool occupied);
  // Marks every cell that the axis-aligned rectangle [min, max] overlaps by more than a
  // hair (1e-9 m).
  void SetRect(const Eigen::Vector2d& min, const Eigen::Vector2d& max, bool occupied);

  // Clearance of cell (ix, iy) (0 for occupied or out-of-bounds cells); requires
  // ComputeClearance after the last Set.
  double Clearance(int ix, int iy) const {
    return InBounds(ix, iy) && !clearance_.empty() ? clearance_[static_cast<std::size_t>(iy) * width_ + ix] : 0.0;
  }
  void ComputeClearance();
  bool has_clearance() const { return !clearance_.empty(); }

 private:
  int width_;
  int height_;
  double resolution_;
  Eigen::Vector2d origin_;
  std::vector<std::uint8_t> cells_;
  std::vector<double> clearance_;
};

}  // namespace dispatch::engine
