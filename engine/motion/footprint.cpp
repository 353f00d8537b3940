#include "engine/motion/footprint.h"

#include <cmath>
#include <stdexcept>

namespace dispatch::engine {

FootprintChecker::FootprintChecker(const OccupancyGrid& grid, const Footprint& footprint)
    : grid_(grid), footprint_(footprint) {
  if (!(footprint.length > 0.0 && footprint.width > 0.0 && footprint.margin >= 0.0)) {
    throw std::invalid_argument("Footprint: length and width > 0, margin >= 0 required");
  }
  const double half_l = footprint.length / 2.0 + footprint.margin;
  const double half_w = footprint.width / 2.0 + footprint.margin;
  circumradius_ = std::hypot(half_l, half_w);
  const double spacing = grid.resolution() / 2.0;
  const int nl = static_cast<int>(std::ceil(2.0 * half_l / spacing));
  const int nw = static_cast<int>(std::ceil(2.0 * half_w / spacing));
  samples_.reserve(static_cast<std::size_t>(nl + 1) * (nw + 1));
  for (int i = 0; i <= nl; ++i) {
    for (int j = 0; j <= nw; ++j) {
      samples_.emplace_back(-half_l + 2.0 * half_l * i / nl, -half_w + 2.0 * half_w * j / nw);
    }
  }
}

bool FootprintChecker::Collides(const MotionPose& pose) const {
  const int cx = grid_.CellX(pose.x);
  const int cy = grid_.CellY(pose.y);
  if (grid_.Occupied(cx, cy)) return true;
  if (grid_.Clearance(cx, cy) > circumradius_ + 2.0 * grid_.resolution()) return false;
  const double c = std::cos(pose.theta);
  const double s = std::sin(pose.theta);
  for (const Eigen::Vector2d& p : samples_) {
    if (grid_.OccupiedAt(pose.x + c * p.x() - s * p.y(), pose.y + s * p.x() + c * p.y())) return true;
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
