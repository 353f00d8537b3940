#include "engine/map/point_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

PointGrid::PointGrid(const std::vector<Point>& points) {
  if (points.empty()) return;
  lo_ = hi_ = points.front().position;
  for (const Point& p : points) {
    lo_ = lo_.cwiseMin(p.position);
    hi_ = hi_.cwiseMax(p.position);
  }
  const Eigen::Vector2d size = hi_ - lo_;
  const double n = static_cast<double>(points.size());
  double cell = std::sqrt(2.0 * size.x() * size.y() / n);
  if (!(cell > 0.0)) cell = std::max(size.x(), size.y()) / n * 2.0;  // points on a line
  if (!(cell > 0.0)) cell = 1.0;                                      // one position
  cell_ = cell;
  inv_cell_ = 1.0 / cell;
  cols_ = static_cast<long>(size.x() * inv_cell_) + 1;
  rows_ = static_cast<long>(size.y() * inv_cell_) + 1;
  std::vector<std::uint32_t> count(static_cast<std::size_t>(cols_ * rows_) + 1, 0);
  std::vector<long> cell_of(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const long cx = std::min(cols_ - 1, static_cast<long>((points[i].position.x() - lo_.x()) * inv_cell_));
    const long cy = std::min(rows_ - 1, static_cast<long>((points[i].position.y() - lo_.y()) * inv_cell_));
    cell_of[i] = cy * cols_ + cx;
    ++count[static_cast<std::size_t>(cell_of[i])];
  }
  begin_.assign(count.size(), 0);
  for (std::size_t c = 1; c < count.size(); ++c) begin_[c] = begin_[c - 1] + count[c - 1];
  ids_.resize(points.size());
  std::vector<std::uint32_t> fill(begin_.begin(), begin_.end() - 1);
  for (std::size_t i = 0; i < points.size(); ++i) {
    ids_[fill[static_cast<std::size_t>(cell_of[i])]++] = static_cast<PointId>(i);
  }
  xy_.reserve(ids_.size());
  for (PointId i : ids_) xy_.push_back(points[static_cast<std::size_t>(i)].position);
  by_id_.reserve(points.size());
  for (const Point& p : points) by_id_.push_back({p.position.x(), p.position.y(), 0.0});
  for (std::size_t i = 0; i < points.size(); ++i) {
    PointId other = kNoPoint;
    double gap = 0.0;
    const Eigen::Vector2d xy(by_id_[i].x, by_id_[i].y);
    if (Search(xy, static_cast<PointId>(i), &other, &gap) && other != kNoPoint) by_id_[i].half_gap = 0.5 * gap;
  }
}

bool PointGrid::NearestFrom(const Eigen::Vector2d& xy, PointId hint, PointId* id, double* distance) const {
  if (Owns(xy, hint, distance)) {
    *id = hint;
    return true;
  }
  return Nearest(xy, id, distance);
}

bool PointGrid::Owns(const Eigen::Vector2d& xy, PointId p, double* distance) const {
  if (p < 0 || static_cast<std::size_t>(p) >= by_id_.size()) return false;
  // Any other point q: |xy - q| >= |p - q| - |xy - p| >= 2 half_gap - d > d.
  const OwnedPoint& o = by_id_[static_cast<std::size_t>(p)];
  const double d = (Eigen::Vector2d(o.x, o.y) - xy).norm();
  if (!(d < o.half_gap * (1.0 - 1e-9))) return false;  // a margin for rounding
  *distance = d;
  return true;
}

bool PointGrid::Nearest(const Eigen::Vector2d& xy, PointId* id, double* distance) const {
  return Search(xy, kNoPoint, id, distance);
}

bool PointGrid::Search(const Eigen::Vector2d& xy, PointId exclude, PointId* id, double* distance) const {
  if (ids_.empty() || !xy.allFinite()) return false;
  if (xy.x() < lo_.x() || xy.y() < lo_.y() || xy.x() > hi_.x() || xy.y() > hi_.y()) return false;
  const long cx = std::min(cols_ - 1, static_cast<long>((xy.x() - lo_.x()) * inv_cell_));
  const long cy = std::min(rows_ - 1, static_cast<long>((xy.y() - lo_.y()) * inv_cell_));
  double best = std::numeric_limits<double>::infinity();
  PointId best_id = kNoPoint;
  auto visit = [&](long x, long y) {
    if (x < 0 || y < 0 || x >= cols_ || y >= rows_) return;
    const auto c = static_cast<std::size_t>(y * cols_ + x);
    for (std::uint32_t k = begin_[c]; k < begin_[c + 1]; ++k) {
      const PointId i = ids_[k];
      if (i == exclude) continue;
      const double d = (xy_[k] - xy).norm();
      if (d < best || (d == best && i < best_id)) {
        best = d;
        best_id = i;
      }
    }
  };
  // Binning rounds, so a point may sit a hair outside its cell's exact edges: keep a margin.
  const double margin = 1e-9 * (1.0 + (hi_ - lo_).norm());
  for (long r = 0;; ++r) {
    if (r == 0) {
      visit(cx, cy);
    } else {
      for (long x = cx - r; x <= cx + r; ++x) {
        visit(x, cy - r);
        visit(x, cy + r);
      }
      for (long y = cy - r + 1; y <= cy + r - 1; ++y) {
        visit(cx - r, y);
        visit(cx + r, y);
      }
    }
    // Distance from xy to the nearest side of the visited square that has cells beyond it.
    double bound = std::numeric_limits<double>::infinity();
    if (cx - r > 0) bound = std::min(bound, xy.x() - (lo_.x() + static_cast<double>(cx - r) * cell_));
    if (cx + r < cols_ - 1) bound = std::min(bound, lo_.x() + static_cast<double>(cx + r + 1) * cell_ - xy.x());
    if (cy - r > 0) bound = std::min(bound, xy.y() - (lo_.y() + static_cast<double>(cy - r) * cell_));
    if (cy + r < rows_ - 1) bound = std::min(bound, lo_.y() + static_cast<double>(cy + r + 1) * cell_ - xy.y());
    if (std::isinf(bound) || best < bound - margin) break;
  }
  *id = best_id;
  *distance = best;
  return true;
}

}  // namespace dispatch::engine
