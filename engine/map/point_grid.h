// PointGrid: a uniform-grid index of a map's points for nearest-point queries
// (WarehouseMap::NearestPoint), so snapping a robot's reported position costs
// O(points in a few cells) instead of a scan of every point: on a 38k-cell LoRR floor with
// 500 robots reporting at 10 Hz the scan alone saturated a core.
//
// Cells of edge ~ sqrt(2 * bounding-box area / points) (about two points a cell), points in
// CSR order. Nearest() searches square rings of cells outward from the query's cell and stops
// once no unvisited cell can hold a closer point; among points at the same distance it
// returns the lowest id, like a scan in id order. Immutable after construction; thread-safe.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace dispatch::engine {

struct Point;
using PointId = std::int32_t;

class PointGrid {
 public:
  PointGrid() = default;
  explicit PointGrid(const std::vector<Point>& points);

  // The nearest of the points the grid was built from (it keeps their positions) to xy and
  // its distance. False when the grid cannot answer: no points, or xy not finite or outside
  // the points' bounding box (the caller scans instead).
  bool Nearest(const Eigen::Vector2d& xy, PointId* id, double* distance) const;
  // The same answer, first trying `hint` (the point a moving robot was nearest to last): a
  // point closer to xy than half the gap to its nearest neighbour is the only nearest one.
  bool NearestFrom(const Eigen::Vector2d& xy, PointId hint, PointId* id, double* distance) const;
  // True when `p` is certainly the only nearest point to xy (closer than half the gap to its
  // nearest neighbour), with its distance; false says nothing.
  bool Owns(const Eigen::Vector2d& xy, PointId p, double* distance) const;

 private:
  Eigen::Vector2d lo_ = Eigen::Vector2d::Zero(), hi_ = Eigen::Vector2d::Zero();
  double cell_ = 1.0, inv_cell_ = 1.0;
  long cols_ = 0, rows_ = 0;
  std::vector<std::uint32_t> begin_;  // per cell (row-major), then one past the end
  std::vector<PointId> ids_;          // point ids by cell, ascending within a cell
  std::vector<Eigen::Vector2d> xy_;   // their positions, side by side (no Point read per query)
  // By point id: its position and half the distance to its nearest other point, side by side
  // (Owns reads both, once per robot report).
  struct alignas(32) OwnedPoint {  // one cache line holds two
    double x = 0.0, y = 0.0;
    double half_gap = 0.0;
  };
  std::vector<OwnedPoint> by_id_;
  bool Search(const Eigen::Vector2d& xy, PointId exclude, PointId* id, double* distance) const;
};

}  // namespace dispatch::engine
