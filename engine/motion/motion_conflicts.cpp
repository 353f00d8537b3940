#include "engine/motion/motion_conflicts.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace dispatch::engine {
namespace {

using Polygon = std::vector<std::pair<double, double>>;

// Separating-axis test for two convex polygons given counter-clockwise: they overlap unless
// some edge normal separates their projections (touching, within 1e-9, separates).
bool ConvexOverlap(const Polygon& p, const Polygon& q) {
  for (const Polygon* poly : {&p, &q}) {
    const std::size_t n = poly->size();
    for (std::size_t i = 0; i < n; ++i) {
      const auto [x0, y0] = (*poly)[i];
      const auto [x1, y1] = (*poly)[(i + 1) % n];
      const double nx = y1 - y0;
      const double ny = x0 - x1;
      double pmin = 1e300, pmax = -1e300, qmin = 1e300, qmax = -1e300;
      for (const auto& [x, y] : p) {
        pmin = std::min(pmin, nx * x + ny * y);
        pmax = std::max(pmax, nx * x + ny * y);
      }
      for (const auto& [x, y] : q) {
        qmin = std::min(qmin, nx * x + ny * y);
        qmax = std::max(qmax, nx * x + ny * y);
      }
      const double scale = 1e-9 * std::hypot(nx, ny);
      if (pmax <= qmin + scale || qmax <= pmin + scale) return false;
    }
  }
  return true;
}

double Circumradius(const Footprint& f, double grow) {
  return std::hypot(f.length / 2.0 + f.margin + grow, f.width / 2.0 + f.margin + grow);
}

}  // namespace

TimedMotionPath TimeMotionPath(MotionPath path, double start_time, const MotionTiming& timing) {
  TimedMotionPath timed;
  timed.start_time = start_time;
  timed.times.reserve(path.poses.size());
  double t = start_time;
  if (!path.poses.empty()) timed.times.push_back(t);
  for (std::size_t i = 0; i + 1 < path.poses.size(); ++i) {
    const MotionPose& a = path.poses[i];
    const MotionPose& b = path.poses[i + 1];
    const bool spin = i < path.modes.size() && IsSpin(path.modes[i]);
    t += spin ? std::abs(WrapHeading(b.theta - a.theta)) / timing.spin_rate
              : std::hypot(b.x - a.x, b.y - a.y) / timing.speed;
    timed.times.push_back(t);
  }
  timed.path = std::move(path);
  return timed;
}

MotionPose PoseAt(const TimedMotionPath& timed, double t) {
  const std::vector<MotionPose>& poses = timed.path.poses;
  if (poses.empty()) return {};
  if (t <= timed.times.front()) return poses.front();
  if (t >= timed.times.back()) return poses.back();
  const auto it = std::upper_bound(timed.times.begin(), timed.times.end(), t);
  const std::size_t j = static_cast<std::size_t>(it - timed.times.begin());  // times[j - 1] <= t < times[j]
  const MotionPose& a = poses[j - 1];
  const MotionPose& b = poses[j];
  const double span = timed.times[j] - timed.times[j - 1];
  const double u = span > 0.0 ? (t - timed.times[j - 1]) / span : 1.0;
  return {a.x + u * (b.x - a.x), a.y + u * (b.y - a.y), WrapHeading(a.theta + u * WrapHeading(b.theta - a.theta))};
}

std::vector<std::pair<double, double>> FootprintCorners(const MotionPose& pose, const Footprint& footprint,
                                                        double grow) {
  const double hl = footprint.length / 2.0 + footprint.margin + grow;
  const double hw = footprint.width / 2.0 + footprint.margin + grow;
  const double c = std::cos(pose.theta);
  const double s = std::sin(pose.theta);
  Polygon corners;
  for (const auto& [l, w] : {std::pair{1.0, -1.0}, std::pair{1.0, 1.0}, std::pair{-1.0, 1.0}, std::pair{-1.0, -1.0}}) {
    corners.emplace_back(pose.x + l * hl * c - w * hw * s, pose.y + l * hl * s + w * hw * c);
  }
  return corners;
}

bool FootprintsOverlap(const MotionPose& a, const Footprint& fa, const MotionPose& b, const Footprint& fb,
                       double grow) {
  const double reach = Circumradius(fa, grow) + Circumradius(fb, grow);
  if (std::hypot(a.x - b.x, a.y - b.y) >= reach) return false;
  return ConvexOverlap(FootprintCorners(a, fa, grow), FootprintCorners(b, fb, grow));
}

std::vector<std::pair<int, int>> FootprintCells(const OccupancyGrid& grid, const MotionPose& pose,
                                                const Footprint& footprint, double grow) {
  const Polygon rect = FootprintCorners(pose, footprint, grow);
  double xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
  for (const auto& [x, y] : rect) {
    xmin = std::min(xmin, x);
    xmax = std::max(xmax, x);
    ymin = std::min(ymin, y);
    ymax = std::max(ymax, y);
  }
  const double res = grid.resolution();
  const double ox = grid.origin().x();
  const double oy = grid.origin().y();
  std::vector<std::pair<int, int>> cells;
  for (int iy = grid.CellY(ymin); iy <= grid.CellY(ymax); ++iy) {
    for (int ix = grid.CellX(xmin); ix <= grid.CellX(xmax); ++ix) {
      const double x0 = ox + ix * res;
      const double y0 = oy + iy * res;
      const Polygon cell = {{x0, y0}, {x0 + res, y0}, {x0 + res, y0 + res}, {x0, y0 + res}};
      if (ConvexOverlap(rect, cell)) cells.emplace_back(ix, iy);
    }
  }
  return cells;
}

std::string Describe(const MotionConflict& c) {
  char buf[200];
  std::snprintf(buf, sizeof buf, "robots %d and %d at t = %.2f s, at (%.2f, %.2f) and (%.2f, %.2f)", c.a, c.b,
                c.time, c.pose_a.x, c.pose_a.y, c.pose_b.x, c.pose_b.y);
  return buf;
}

std::optional<MotionConflict> FirstMotionConflict(const std::vector<TimedMotionPath>& paths,
                                                  const std::vector<Footprint>& footprints,
                                                  const MotionConflictOptions& options) {
  double horizon = 0.0;
  for (const TimedMotionPath& p : paths) horizon = std::max(horizon, p.arrival());
  const double grow = options.clearance / 2.0;
  const long samples = static_cast<long>(std::ceil(horizon / options.time_step - 1e-9));
  std::vector<MotionPose> at(paths.size());
  for (long k = 0; k <= samples; ++k) {
    const double t = std::min(horizon, static_cast<double>(k) * options.time_step);
    for (std::size_t i = 0; i < paths.size(); ++i) at[i] = PoseAt(paths[i], t);
    for (std::size_t a = 0; a < paths.size(); ++a) {
      for (std::size_t b = a + 1; b < paths.size(); ++b) {
        if (FootprintsOverlap(at[a], footprints[a], at[b], footprints[b], grow)) {
          return MotionConflict{static_cast<int>(a), static_cast<int>(b), t, at[a], at[b]};
        }
      }
    }
  }
  return std::nullopt;
}

Status CheckTimedMotionPaths(const std::vector<TimedMotionPath>& paths, const std::vector<Footprint>& footprints,
                             const MotionConflictOptions& options) {
  if (paths.size() != footprints.size()) return InvalidArgument("timed paths: one footprint per path required");
  if (!(options.time_step > 0.0) || options.clearance < 0.0) return InvalidArgument("timed paths: bad options");
  for (std::size_t i = 0; i < paths.size(); ++i) {
    const TimedMotionPath& p = paths[i];
    const std::string who = "robot " + std::to_string(i) + ": ";
    if (p.path.poses.empty() || p.times.size() != p.path.poses.size()) {
      return InvalidArgument(who + "needs one time per pose and at least one pose");
    }
    if (p.times.front() != p.start_time || p.start_time < 0.0) return InvalidArgument(who + "bad start time");
    for (std::size_t k = 1; k < p.times.size(); ++k) {
      if (!(p.times[k] >= p.times[k - 1])) return InvalidArgument(who + "times go backwards");
    }
  }
  if (const auto c = FirstMotionConflict(paths, footprints, options)) {
    return Error{ErrorCode::kFailedPrecondition, "conflict: " + Describe(*c)};
  }
  return Ok{};
}

}  // namespace dispatch::engine
