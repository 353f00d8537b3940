#include "engine/motion/footprint.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace dispatch::engine {

FootprintChecker::FootprintChecker(const OccupancyGrid& grid, const Footprint& footprint)
    : grid_(grid), footprint_(footprint) {
  if (!(footprint.length > 0.0 && footprint.width > 0.0 && footprint.margin >= 0.0)) {
    throw std::invalid_argument("Footprint: length and width > 0, margin >= 0 required");
  }
  half_length_ = footprint.length / 2.0 + footprint.margin;
  half_width_ = footprint.width / 2.0 + footprint.margin;
  circumradius_ = std::hypot(half_length_, half_width_);
  const int w = grid.width();
  row_prefix_.assign(static_cast<std::size_t>(w + 1) * grid.height(), 0);
  for (int iy = 0; iy < grid.height(); ++iy) {
    int* row = &row_prefix_[static_cast<std::size_t>(iy) * (w + 1)];
    for (int ix = 0; ix < w; ++ix) row[ix + 1] = row[ix] + (grid.Occupied(ix, iy) ? 1 : 0);
  }
}

bool FootprintChecker::Collides(const MotionPose& pose) const {
  const int cx = grid_.CellX(pose.x);
  const int cy = grid_.CellY(pose.y);
  if (grid_.Occupied(cx, cy)) return true;
  if (grid_.Clearance(cx, cy) > circumradius_ + 2.0 * grid_.resolution()) return false;
  // Corners in grid units (origin at the grid's corner, one unit per cell), in order.
  const double res = grid_.resolution();
  const double c = std::cos(pose.theta);
  const double s = std::sin(pose.theta);
  const double px = (pose.x - grid_.origin().x()) / res;
  const double py = (pose.y - grid_.origin().y()) / res;
  const double lx = c * half_length_ / res, ly = s * half_length_ / res;   // half the length axis
  const double wx = -s * half_width_ / res, wy = c * half_width_ / res;    // half the width axis
  const double xs[4] = {px + lx + wx, px - lx + wx, px - lx - wx, px + lx - wx};
  const double ys[4] = {py + ly + wy, py - ly + wy, py - ly - wy, py + ly - wy};
  const double ymin = std::min({ys[0], ys[1], ys[2], ys[3]});
  const double ymax = std::max({ys[0], ys[1], ys[2], ys[3]});
  const int iy0 = static_cast<int>(std::floor(ymin));
  const int iy1 = static_cast<int>(std::ceil(ymax)) - 1;
  if (iy0 < 0 || iy1 >= grid_.height()) return true;
  const int w = grid_.width();
  for (int iy = iy0; iy <= iy1; ++iy) {
    // The rectangle clipped to the strip iy <= y <= iy + 1: its x-extent is that of its
    // edges clipped to the strip (it is convex).
    const double ya = iy;
    const double yb = iy + 1.0;
    double xmin = 1e300;
    double xmax = -1e300;
    for (int e = 0; e < 4; ++e) {
      const double x0 = xs[e], y0 = ys[e], x1 = xs[(e + 1) % 4], y1 = ys[(e + 1) % 4];
      double t0 = 0.0, t1 = 1.0;
      const double dy = y1 - y0;
      if (std::abs(dy) < 1e-12) {
        if (y0 < ya || y0 > yb) continue;
      } else {
        double ta = (ya - y0) / dy;
        double tb = (yb - y0) / dy;
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
        if (t0 > t1) continue;
      }
      const double xa = x0 + (x1 - x0) * t0;
      const double xb = x0 + (x1 - x0) * t1;
      xmin = std::min({xmin, xa, xb});
      xmax = std::max({xmax, xa, xb});
    }
    if (xmin > xmax) continue;
    const int ix0 = static_cast<int>(std::floor(xmin));
    const int ix1 = static_cast<int>(std::ceil(xmax)) - 1;
    if (ix0 < 0 || ix1 >= w) return true;
    if (ix1 < ix0) continue;
    const int* row = &row_prefix_[static_cast<std::size_t>(iy) * (w + 1)];
    if (row[ix1 + 1] - row[ix0] > 0) return true;
  }
  return false;
}

bool FootprintChecker::AnyCollides(const std::vector<MotionPose>& poses) const {
  for (const MotionPose& pose : poses) {
    if (Collides(pose)) return true;
  }
  return false;
}

}  // namespace dispatch::engine
