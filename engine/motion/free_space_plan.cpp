#include "engine/motion/free_space_plan.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <optional>
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
      // The poses kept, timed; the last pose is the next anchor's.
      struct Kept {
        MotionPose pose;
        double t;
        MotionMode mode;
      };
      std::vector<Kept> kept;
      std::optional<MotionMode> last_mode;
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
        last_mode = mode;
        const bool last = k + 2 == poses.size();
        if (!last && (modes[k + 1] != mode || progress >= options_.keep_every)) {
          kept.push_back({q, t, mode});
          progress = 0.0;
        }
      }
      // Names: the graph route between the anchors (anchors[a] .. anchors[a + 1] of the input,
      // consecutive points joined by arcs) in order, each on the kept pose nearest to it (not
      // before the previous one's), so the traffic gate sees the robot pass the route's points
      // one after another. A route point no pose is nearest to gets a waypoint of its own at
      // the same pose and time.
      const std::size_t first_index = anchors[a], last_index = anchors[a + 1];
      std::vector<std::size_t> pose_of(last_index - first_index, kept.size());  // by m - first_index
      for (std::size_t m = first_index + 1, from_pose = 0; m < last_index; ++m) {
        double best_d = std::numeric_limits<double>::infinity();
        for (std::size_t q = from_pose; q < kept.size(); ++q) {
          const double d = (Eigen::Vector2d(kept[q].pose.x, kept[q].pose.y) - in[m].xy).squaredNorm();
          if (d < best_d) best_d = d, pose_of[m - first_index] = q;
        }
        from_pose = std::min(pose_of[m - first_index], kept.size());
      }
      auto emit = [&](const Kept& k, PointId point) {
        Waypoint w;
        w.point = point;
        w.xy = Eigen::Vector2d(k.pose.x, k.pose.y);
        w.eta = k.t;
        w.action = WaypointAction::kMove;
        w.heading = k.pose.theta;
        w.mode = k.mode;
        push(std::move(w));
      };
      PointId label = from.point;
      std::size_t m = first_index + 1;  // the next route point to name
      for (std::size_t q = 0; q < kept.size(); ++q) {
        while (m < last_index && pose_of[m - first_index] == q) {
          if (m + 1 < last_index && pose_of[m + 1 - first_index] == q) emit(kept[q], in[m].point);
          label = in[m++].point;
        }
        emit(kept[q], label);
      }
      for (; m < last_index; ++m) {  // route points no kept pose is nearest to: just before the anchor
        emit(kept.empty() ? Kept{goal, t, last_mode.value_or(MotionMode::kForward)} : kept.back(), in[m].point);
      }
      Waypoint w = to;
      w.eta = t;
      w.heading = goal.theta;
      w.mode = last_mode;
      t += w.dwell;
      push(std::move(w));
    }
    shift = out.waypoints.back().eta - in[j].eta;
    i = j + 1;
  }
  return out;
}

}  // namespace dispatch::engine
