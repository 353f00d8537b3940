#include "engine/motion/free_space_plan.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>
#include <utility>

#include "engine/motion/free_space_grid.h"

namespace dispatch::engine {
namespace {

constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();

std::string PoseText(const std::string& point, const MotionPose& p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, " (%.2f, %.2f, %.0f deg)", p.x, p.y, p.theta * 180.0 / std::numbers::pi);
  return "'" + point + "'" + buf;
}

// Heading of the move from a to b, or nullopt when they are one place.
std::optional<double> Direction(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d d = b - a;
  if (d.norm() < 1e-9) return std::nullopt;
  return std::atan2(d.y(), d.x());
}

// The graph heading of waypoint k: the arc it is reached by, else the arc it leaves by.
double ArrivalHeading(const std::vector<Waypoint>& w, std::size_t k) {
  for (std::size_t p = k; p-- > 0;) {
    if (auto d = Direction(w[p].xy, w[k].xy)) return *d;
  }
  for (std::size_t q = k + 1; q < w.size(); ++q) {
    if (auto d = Direction(w[k].xy, w[q].xy)) return *d;
  }
  return 0.0;
}

double DepartureHeading(const std::vector<Waypoint>& w, std::size_t k) {
  for (std::size_t q = k + 1; q < w.size(); ++q) {
    if (auto d = Direction(w[k].xy, w[q].xy)) return *d;
  }
  return ArrivalHeading(w, k);
}

bool IsStop(const Waypoint& w) { return w.action != WaypointAction::kMove || w.dwell > 0.0; }

}  // namespace

Result<FreeSpaceMotion> FreeSpaceMotion::Create(std::shared_ptr<const WarehouseMap> map,
                                                FreeSpaceMotionOptions options) {
  if (!map) return InvalidArgument("free space motion: no map");
  if (!(options.spin_rate > 0.0) || !std::isfinite(options.spin_rate)) {
    return InvalidArgument("free space motion: spin_rate must be > 0 rad/s");
  }
  if (!(options.keep_every > 0.0) || !std::isfinite(options.keep_every)) {
    return InvalidArgument("free space motion: keep_every must be > 0");
  }
  if (!(options.footprint.length > 0.0) || !(options.footprint.width > 0.0) ||
      !(options.footprint.margin >= 0.0)) {
    return InvalidArgument("free space motion: the footprint needs length, width > 0 and margin >= 0");
  }
  FreeSpaceMotion out;
  out.map_ = std::move(map);
  out.options_ = std::move(options);
  out.region_of_point_.assign(out.map_->point_count(), kNone);
  const auto& spaces = out.map_->free_spaces();
  for (std::size_t r = 0; r < spaces.size(); ++r) {
    Result<OccupancyGrid> grid = FreeSpaceGrid(*out.map_, r, out.options_.resolution);
    if (!grid.ok()) return grid.error();
    out.regions_.push_back(std::make_unique<Region>(std::move(grid).value(), out.options_.footprint));
    for (PointId p : spaces[r].points) {
      std::size_t& slot = out.region_of_point_[static_cast<std::size_t>(p)];
      if (slot == kNone) slot = r;
    }
  }
  return out;
}

std::size_t FreeSpaceMotion::RegionOf(PointId point) const {
  if (point < 0 || static_cast<std::size_t>(point) >= region_of_point_.size()) return kNone;
  return region_of_point_[static_cast<std::size_t>(point)];
}

Result<Plan> FreeSpaceMotion::Refine(const Plan& plan, double speed,
                                     const std::map<std::size_t, double>& stop_headings) const {
  if (!(speed > 0.0) || !std::isfinite(speed)) {
    return InvalidArgument("free space motion: speed must be > 0 m/s");
  }
  const std::vector<Waypoint>& in = plan.waypoints;
  const std::size_t n = in.size();
  Plan out;
  out.robot_id = plan.robot_id;
  double shift = 0.0;  // new time - old time, for waypoints after the last replaced stretch
  auto push = [&](Waypoint w) {
    w.seq = in.empty() ? 0 : in.front().seq + static_cast<int>(out.waypoints.size());
    out.waypoints.push_back(std::move(w));
  };
  std::size_t i = 0;
  while (i < n) {
    const std::size_t r = RegionOf(in[i].point);
    if (r == kNone) {
      Waypoint w = in[i++];
      w.eta += shift;
      push(std::move(w));
      continue;
    }
    std::size_t j = i;
    while (j + 1 < n && RegionOf(in[j + 1].point) == r) ++j;
    // Anchors and their headings.
    std::vector<std::size_t> anchors{i};
    for (std::size_t k = i + 1; k < j; ++k) {
      if (IsStop(in[k]) || stop_headings.count(k) > 0) anchors.push_back(k);
    }
    if (j > i) anchors.push_back(j);
    auto heading_of = [&](std::size_t k) {
      if (auto it = stop_headings.find(k); it != stop_headings.end()) return WrapHeading(it->second);
      if (k == j && j + 1 < n) return DepartureHeading(in, k);
      return ArrivalHeading(in, k);
    };
    Waypoint first = in[i];
    first.eta += shift;
    first.heading = heading_of(i);
    const double first_departure = first.departure();
    push(std::move(first));
    double t = first_departure;  // departure from the last anchor
    const FreeSpace& space = map_->free_spaces()[r];
    const Region& region = *regions_[r];
    auto nearest_point = [&](const MotionPose& pose) {
      PointId best = in[i].point;
      double best_d = std::numeric_limits<double>::infinity();
      for (PointId p : space.points) {
        const double d = (map_->point(p).position - Eigen::Vector2d(pose.x, pose.y)).squaredNorm();
        if (d < best_d) best_d = d, best = p;
      }
      return best;
    };
    for (std::size_t a = 0; a + 1 < anchors.size(); ++a) {
      const Waypoint& from = in[anchors[a]];
      const Waypoint& to = in[anchors[a + 1]];
      const MotionPose start{from.xy.x(), from.xy.y(), out.waypoints.back().heading.value()};
      const MotionPose goal{to.xy.x(), to.xy.y(), heading_of(anchors[a + 1])};
      Result<MotionPath> path = PlanHybridAStar(region.checker, start, goal, options_.search);
      if (!path.ok()) {
        return Error{path.error().code, "free space '" + space.name + "': from " +
                                            PoseText(map_->point(from.point).name, start) + " to " +
                                            PoseText(map_->point(to.point).name, goal) + ": " +
                                            path.error().message};
      }
      const std::vector<MotionPose>& poses = path->poses;
      const std::vector<MotionMode>& modes = path->modes;
      double progress = 0.0;  // since the last kept pose
      for (std::size_t k = 0; k + 1 < poses.size(); ++k) {
        const MotionPose& p = poses[k];
        const MotionPose& q = poses[k + 1];
        const MotionMode mode = modes[k];
        double amount;
        if (IsSpin(mode)) {
          amount = std::abs(WrapHeading(q.theta - p.theta));
          t += amount / options_.spin_rate;
        } else {
          amount = IsArc(mode) ? std::abs(WrapHeading(q.theta - p.theta)) * options_.search.min_turn_radius
                               : std::hypot(q.x - p.x, q.y - p.y);
          t += amount / speed;
        }
        progress += amount;
        const bool last = k + 2 == poses.size();
        const bool mode_ends = !last && modes[k + 1] != mode;
        if (last) {
          Waypoint w = to;
          w.eta = t;
          w.heading = goal.theta;
          w.mode = mode;
          t += w.dwell;
          push(std::move(w));
        } else if (mode_ends || progress >= options_.keep_every) {
          Waypoint w;
          w.point = nearest_point(q);
          w.xy = Eigen::Vector2d(q.x, q.y);
          w.eta = t;
          w.action = WaypointAction::kMove;
          w.heading = q.theta;
          w.mode = mode;
          push(std::move(w));
          progress = 0.0;
        }
      }
      if (poses.size() < 2) {  // already there: the anchor as it is, at once
        Waypoint w = to;
        w.eta = t;
        w.heading = goal.theta;
        t += w.dwell;
        push(std::move(w));
      }
    }
    shift = out.waypoints.back().eta - in[j].eta;
    i = j + 1;
  }
  return out;
}

}  // namespace dispatch::engine
