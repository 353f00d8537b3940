#include "engine/map/warehouse_map.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dispatch::engine {

namespace {
constexpr const char* kKindNames[] = {"lane", "intersection", "pick", "drop", "park", "charge"};
}  // namespace

const char* PointKindName(PointKind kind) { return kKindNames[static_cast<int>(kind)]; }

std::optional<PointKind> ParsePointKind(const std::string& name) {
  for (int i = 0; i < 6; ++i) {
    if (name == kKindNames[i]) return static_cast<PointKind>(i);
  }
  return std::nullopt;
}

bool IsServicePoint(PointKind kind) {
  return kind == PointKind::kPick || kind == PointKind::kDrop || kind == PointKind::kPark ||
         kind == PointKind::kCharge;
}

bool PolygonContains(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& p) {
  constexpr double kEps = 1e-9;
  const std::size_t n = polygon.size();
  bool inside = false;
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[j];
    // On the edge a-b: collinear and within its bounding box.
    const double cross = (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x());
    if (std::abs(cross) <= kEps * std::max(1.0, (b - a).norm()) &&
        p.x() >= std::min(a.x(), b.x()) - kEps && p.x() <= std::max(a.x(), b.x()) + kEps &&
        p.y() >= std::min(a.y(), b.y()) - kEps && p.y() <= std::max(a.y(), b.y()) + kEps) {
      return true;
    }
    if ((a.y() > p.y()) != (b.y() > p.y())) {
      const double x_cross = a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
      if (p.x() < x_cross) inside = !inside;
    }
  }
  return inside;
}

std::optional<PointId> WarehouseMap::FindPoint(const std::string& name) const {
  auto it = point_index_.find(name);
  if (it == point_index_.end()) return std::nullopt;
  return it->second;
}

std::optional<ZoneId> WarehouseMap::FindZone(const std::string& name) const {
  auto it = zone_index_.find(name);
  if (it == zone_index_.end()) return std::nullopt;
  return it->second;
}

std::optional<ArcId> WarehouseMap::FindArc(PointId from, PointId to) const {
  if (from < 0 || static_cast<std::size_t>(from) >= points_.size()) return std::nullopt;
  for (ArcId a : out_arcs(from)) {
    if (arcs_[static_cast<std::size_t>(a)].to == to) return a;
  }
  return std::nullopt;
}

Eigen::Vector2d WarehouseMap::PositionOf(const ArcPosition& pos) const {
  const Arc& a = arc(pos.arc);
  const Eigen::Vector2d& p0 = point(a.from).position;
  const Eigen::Vector2d& p1 = point(a.to).position;
  const double t = a.length > 0 ? std::clamp(pos.offset / a.length, 0.0, 1.0) : 0.0;
  return p0 + t * (p1 - p0);
}

Result<ArcPosition> WarehouseMap::NearestArcPosition(const Eigen::Vector2d& xy,
                                                     double* distance) const {
  if (arcs_.empty()) return InvalidArgument("map '" + name_ + "' has no paths to project onto");
  double best = std::numeric_limits<double>::infinity();
  ArcPosition best_pos;
  for (std::size_t i = 0; i < arcs_.size(); ++i) {
    const Arc& a = arcs_[i];
    const Eigen::Vector2d p0 = points_[static_cast<std::size_t>(a.from)].position;
    const Eigen::Vector2d d = points_[static_cast<std::size_t>(a.to)].position - p0;
    const double len2 = d.squaredNorm();
    const double t = len2 > 0 ? std::clamp((xy - p0).dot(d) / len2, 0.0, 1.0) : 0.0;
    const double dist = (p0 + t * d - xy).norm();
    if (dist < best) {
      best = dist;
      best_pos = {static_cast<ArcId>(i), t * a.length};
    }
  }
  if (distance) *distance = best;
  return best_pos;
}

PointId WarehouseMap::NearestPointFrom(const Eigen::Vector2d& xy, PointId hint) const {
  double d = 0.0;
  if (point_grid_.Owns(xy, hint, &d)) return hint;
  // A robot driving on from its last point is on one of that point's arcs: past half way the
  // arc's other end is the one it is nearest to.
  if (hint >= 0 && static_cast<std::size_t>(hint) < points_.size()) {
    for (ArcId a : out_arcs_[static_cast<std::size_t>(hint)]) {
      if (const PointId q = arcs_[static_cast<std::size_t>(a)].to; point_grid_.Owns(xy, q, &d)) return q;
    }
    for (ArcId a : in_arcs_[static_cast<std::size_t>(hint)]) {
      if (const PointId q = arcs_[static_cast<std::size_t>(a)].from; point_grid_.Owns(xy, q, &d)) return q;
    }
  }
  return NearestPoint(xy);
}

PointId WarehouseMap::NearestPoint(const Eigen::Vector2d& xy, std::optional<PointKind> kind,
                                   double* distance) const {
  double best = std::numeric_limits<double>::infinity();
  PointId best_id = kNoPoint;
  if (!kind && point_grid_.Nearest(xy, &best_id, &best)) {
    if (distance) *distance = best;
    return best_id;
  }
  for (std::size_t i = 0; i < points_.size(); ++i) {
    if (kind && points_[i].kind != *kind) continue;
    const double dist = (points_[i].position - xy).norm();
    if (dist < best) {
      best = dist;
      best_id = static_cast<PointId>(i);
    }
  }
  if (distance) *distance = best;
  return best_id;
}

}  // namespace dispatch::engine
