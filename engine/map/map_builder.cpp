#include "engine/map/map_builder.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <set>
#include <sstream>
#include <unordered_set>

#include "engine/common/text.h"

namespace dispatch::engine {

namespace {

std::string Fmt(const Eigen::Vector2d& p) {
  std::ostringstream out;
  out << "(" << p.x() << ", " << p.y() << ")";
  return out.str();
}

double PolygonArea(const std::vector<Eigen::Vector2d>& poly) {
  double twice = 0.0;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    twice += poly[j].x() * poly[i].y() - poly[i].x() * poly[j].y();
  }
  return std::abs(twice) / 2.0;
}

bool Finite(const Eigen::Vector2d& p) { return std::isfinite(p.x()) && std::isfinite(p.y()); }

double Cross(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

// Proper crossing of segments ab and cd (shared endpoints and touching do not count).
bool SegmentsCross(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                   const Eigen::Vector2d& d) {
  const double d1 = Cross(c, d, a), d2 = Cross(c, d, b), d3 = Cross(a, b, c), d4 = Cross(a, b, d);
  return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

bool SelfIntersecting(const std::vector<Eigen::Vector2d>& poly) {
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // adjacent through the closing edge
      if (SegmentsCross(poly[i], poly[(i + 1) % n], poly[j], poly[(j + 1) % n])) return true;
    }
  }
  return false;
}

// A zone's or free space's polygon: >= 3 finite vertices, positive area, not crossing itself,
// on the floor (if one is set). Returns its area.
Result<double> CheckPolygon(const std::string& where, const std::vector<Eigen::Vector2d>& polygon,
                            const std::optional<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& floor) {
  if (polygon.size() < 3) return InvalidArgument(where + ": polygon needs >= 3 vertices");
  for (const auto& v : polygon) {
    if (!Finite(v)) return InvalidArgument(where + ": vertex is not a finite number");
  }
  const double area = PolygonArea(polygon);
  if (!(area > 0)) return InvalidArgument(where + ": area is zero");
  if (SelfIntersecting(polygon)) {
    return InvalidArgument(where + ": polygon crosses itself, so its area is undefined");
  }
  if (floor) {
    for (const auto& v : polygon) {
      if ((v.array() < floor->first.array() - 1e-9).any() || (v.array() > floor->second.array() + 1e-9).any()) {
        return InvalidArgument(where + ": vertex " + Fmt(v) + " lies outside the floor");
      }
    }
  }
  return area;
}

// Points reachable from `start` following arcs forward (or backward).
std::vector<char> Reach(const WarehouseMap& map, PointId start, bool forward) {
  std::vector<char> seen(map.point_count(), 0);
  std::deque<PointId> queue{start};
  seen[static_cast<std::size_t>(start)] = 1;
  while (!queue.empty()) {
    const PointId p = queue.front();
    queue.pop_front();
    for (ArcId a : forward ? map.out_arcs(p) : map.in_arcs(p)) {
      const PointId q = forward ? map.arc(a).to : map.arc(a).from;
      if (!seen[static_cast<std::size_t>(q)]) {
        seen[static_cast<std::size_t>(q)] = 1;
        queue.push_back(q);
      }
    }
  }
  return seen;
}

}  // namespace

void MapBuilder::SetFloor(const Eigen::Vector2d& min, const Eigen::Vector2d& max) {
  floor_ = std::make_pair(min, max);
}

void MapBuilder::AddZone(std::string name, std::vector<Eigen::Vector2d> polygon) {
  Zone zone;
  zone.name = std::move(name);
  zone.polygon = std::move(polygon);
  zones_.push_back(std::move(zone));
}

void MapBuilder::AddRectZone(std::string name, const Eigen::Vector2d& min,
                             const Eigen::Vector2d& max) {
  AddZone(std::move(name), {min, {max.x(), min.y()}, max, {min.x(), max.y()}});
}

void MapBuilder::AddPoint(std::string name, const Eigen::Vector2d& position, PointKind kind,
                          std::string zone) {
  point_names_.emplace(name, points_.size());
  points_.push_back({std::move(name), position, kind, std::move(zone)});
}

void MapBuilder::AddPath(std::string from, std::string to, std::optional<double> length,
                         double max_speed, bool bidirectional) {
  paths_.push_back({std::move(from), std::move(to), length, max_speed, bidirectional});
}

void MapBuilder::AddIntersection(std::string name, std::vector<std::string> inner,
                                 std::vector<std::string> approach) {
  intersections_.push_back({std::move(name), std::move(inner), std::move(approach)});
}

void MapBuilder::AddStation(std::string name, std::string point, int capacity) {
  stations_.push_back({std::move(name), std::move(point), capacity});
}

void MapBuilder::AddFreeSpace(std::string name, std::vector<Eigen::Vector2d> polygon) {
  FreeSpace space;
  space.name = std::move(name);
  space.polygon = std::move(polygon);
  free_spaces_.push_back(std::move(space));
}

void MapBuilder::AddShelf(std::string name, const Eigen::Vector2d& min,
                          const Eigen::Vector2d& max) {
  shelves_.push_back({std::move(name), min, max});
}

bool MapBuilder::HasPoint(const std::string& name) const { return point_names_.count(name) > 0; }

Result<WarehouseMap> MapBuilder::Build(const MapBuildOptions& options) const {
  WarehouseMap map;
  map.name_ = name_;

  // Zones.
  if (zones_.empty()) return InvalidArgument("map '" + name_ + "' has no zones");
  for (std::size_t i = 0; i < zones_.size(); ++i) {
    Zone zone = zones_[i];
    const std::string where = "zone " + std::to_string(i) + " ('" + zone.name + "')";
    if (zone.name.empty()) return InvalidArgument(where + ": empty id");
    Result<double> area = CheckPolygon(where, zone.polygon, floor_);
    if (!area.ok()) return area.error();
    zone.area = *area;
    if (!map.zone_index_.emplace(zone.name, static_cast<ZoneId>(i)).second) {
      return InvalidArgument(where + ": duplicate zone id");
    }
    map.zones_.push_back(std::move(zone));
  }

  // Points.
  if (points_.empty()) return InvalidArgument("map '" + name_ + "' has no points");
  map.points_.reserve(points_.size());
  for (std::size_t i = 0; i < points_.size(); ++i) {
    const PointSpec& spec = points_[i];
    const std::string where = "point " + std::to_string(i) + " ('" + spec.name + "')";
    if (spec.name.empty()) return InvalidArgument(where + ": empty id");
    if (!Finite(spec.position)) return InvalidArgument(where + ": coordinates are not finite");
    if (!map.point_index_.emplace(spec.name, static_cast<PointId>(i)).second) {
      return InvalidArgument(where + ": duplicate point id");
    }
    Point point{spec.name, spec.position, spec.kind, -1};
    if (!spec.zone.empty()) {
      auto z = map.FindZone(spec.zone);
      if (!z) return InvalidArgument(where + ": unknown zone '" + spec.zone + "'");
      if (!map.zones_[static_cast<std::size_t>(*z)].Contains(spec.position)) {
        return InvalidArgument(where + " at " + Fmt(spec.position) + " lies outside its zone '" +
                               spec.zone + "'");
      }
      point.zone = *z;
    } else {
      for (std::size_t z = 0; z < map.zones_.size(); ++z) {
        if (map.zones_[z].Contains(spec.position)) {
          point.zone = static_cast<ZoneId>(z);
          break;
        }
      }
      if (point.zone < 0) {
        return InvalidArgument(where + " at " + Fmt(spec.position) + " lies in no zone");
      }
    }
    map.points_.push_back(std::move(point));
  }

  // Floor: given, or the bounding box of everything.
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  for (const Point& p : map.points_) {
    lo = lo.cwiseMin(p.position);
    hi = hi.cwiseMax(p.position);
  }
  if (floor_) {
    const auto& [fmin, fmax] = *floor_;
    if (!Finite(fmin) || !Finite(fmax) || !(fmin.x() < fmax.x()) || !(fmin.y() < fmax.y())) {
      return InvalidArgument("floor: min " + Fmt(fmin) + " must be below max " + Fmt(fmax));
    }
    for (const Point& p : map.points_) {
      if ((p.position.array() < fmin.array()).any() || (p.position.array() > fmax.array()).any()) {
        return InvalidArgument("point '" + p.name + "' at " + Fmt(p.position) +
                               " lies outside the floor");
      }
    }
    map.floor_min_ = fmin;
    map.floor_max_ = fmax;
  } else {
    for (const Zone& z : map.zones_) {
      for (const auto& v : z.polygon) {
        lo = lo.cwiseMin(v);
        hi = hi.cwiseMax(v);
      }
    }
    map.floor_min_ = lo;
    map.floor_max_ = hi;
  }

  // Paths and the arcs derived from them.
  map.out_arcs_.assign(map.points_.size(), {});
  map.in_arcs_.assign(map.points_.size(), {});
  std::set<std::pair<PointId, PointId>> arc_ends;
  auto add_arc = [&](const Path& path, std::int32_t path_index, PointId from, PointId to) {
    const ArcId id = static_cast<ArcId>(map.arcs_.size());
    map.arcs_.push_back({from, to, path.length, path.max_speed, path_index, -1});
    map.out_arcs_[static_cast<std::size_t>(from)].push_back(id);
    map.in_arcs_[static_cast<std::size_t>(to)].push_back(id);
    return id;
  };
  for (std::size_t i = 0; i < paths_.size(); ++i) {
    const PathSpec& spec = paths_[i];
    const std::string where = "path " + std::to_string(i) + " (" + spec.from + " -> " + spec.to + ")";
    auto from = map.FindPoint(spec.from);
    if (!from) return InvalidArgument(where + ": unknown point '" + spec.from + "'");
    auto to = map.FindPoint(spec.to);
    if (!to) return InvalidArgument(where + ": unknown point '" + spec.to + "'");
    if (*from == *to) return InvalidArgument(where + ": both ends are the same point");
    const double straight = (map.point(*to).position - map.point(*from).position).norm();
    const double length = spec.length.value_or(straight);
    if (!std::isfinite(length) || !(length > 0)) {
      return InvalidArgument(where + ": length must be a positive number of metres, got " +
                             Number(length));
    }
    if (length < straight - 1e-6) {
      return InvalidArgument(where + ": length " + Number(length) +
                             " is shorter than the straight distance " + Number(straight));
    }
    if (!std::isfinite(spec.max_speed) || spec.max_speed < 0) {
      return InvalidArgument(where + ": max_speed must be >= 0 (0 = no limit)");
    }
    if (!arc_ends.insert({*from, *to}).second ||
        (spec.bidirectional && !arc_ends.insert({*to, *from}).second)) {
      return InvalidArgument(where + ": duplicate path between the same points");
    }
    Path path{*from, *to, length, spec.max_speed, spec.bidirectional};
    const auto index = static_cast<std::int32_t>(i);
    const ArcId forward = add_arc(path, index, *from, *to);
    if (spec.bidirectional) {
      const ArcId backward = add_arc(path, index, *to, *from);
      map.arcs_[static_cast<std::size_t>(forward)].reverse_arc = backward;
      map.arcs_[static_cast<std::size_t>(backward)].reverse_arc = forward;
    }
    map.paths_.push_back(path);
  }

  // Intersections.
  map.intersection_of_.assign(map.points_.size(), -1);
  std::unordered_set<std::string> names;
  for (std::size_t i = 0; i < intersections_.size(); ++i) {
    const IntersectionSpec& spec = intersections_[i];
    const std::string where = "intersection " + std::to_string(i) + " ('" + spec.name + "')";
    if (spec.name.empty()) return InvalidArgument(where + ": empty id");
    if (!names.insert(spec.name).second) return InvalidArgument(where + ": duplicate id");
    if (spec.inner.empty()) return InvalidArgument(where + ": inner region is empty");
    if (spec.approach.empty()) return InvalidArgument(where + ": has no approach points");
    Intersection inter{spec.name, {}, {}};
    for (const std::string& n : spec.inner) {
      auto p = map.FindPoint(n);
      if (!p) return InvalidArgument(where + ": unknown inner point '" + n + "'");
      int& owner = map.intersection_of_[static_cast<std::size_t>(*p)];
      if (owner == static_cast<int>(i)) {
        return InvalidArgument(where + ": inner point '" + n + "' is listed twice");
      }
      if (owner >= 0) {
        return InvalidArgument(where + ": point '" + n + "' is already inside intersection '" +
                               map.intersections_[static_cast<std::size_t>(owner)].name + "'");
      }
      owner = static_cast<int>(i);
      inter.inner.push_back(*p);
    }
    for (const std::string& n : spec.approach) {
      auto p = map.FindPoint(n);
      if (!p) return InvalidArgument(where + ": unknown approach point '" + n + "'");
      if (std::find(inter.approach.begin(), inter.approach.end(), *p) != inter.approach.end()) {
        return InvalidArgument(where + ": approach point '" + n + "' is listed twice");
      }
      inter.approach.push_back(*p);
    }
    map.intersections_.push_back(std::move(inter));
  }
  // Approach points lie outside every inner region (checked once all regions are known).
  for (const Intersection& inter : map.intersections_) {
    for (PointId p : inter.approach) {
      const int owner = map.intersection_of_[static_cast<std::size_t>(p)];
      if (owner < 0) continue;
      const std::string& other = map.intersections_[static_cast<std::size_t>(owner)].name;
      return InvalidArgument("intersection '" + inter.name + "': approach point '" +
                             map.point(p).name + "' lies inside intersection '" + other + "'" +
                             (other == inter.name ? " (both inner and approach)" : ""));
    }
  }

  // Stations.
  names.clear();
  for (std::size_t i = 0; i < stations_.size(); ++i) {
    const StationSpec& spec = stations_[i];
    const std::string where = "station " + std::to_string(i) + " ('" + spec.name + "')";
    if (spec.name.empty()) return InvalidArgument(where + ": empty id");
    if (!names.insert(spec.name).second) return InvalidArgument(where + ": duplicate id");
    auto p = map.FindPoint(spec.point);
    if (!p) return InvalidArgument(where + ": unknown point '" + spec.point + "'");
    if (map.point(*p).kind != PointKind::kPark && map.point(*p).kind != PointKind::kCharge) {
      return InvalidArgument(where + ": point '" + spec.point + "' is a " +
                             PointKindName(map.point(*p).kind) + " point, not park or charge");
    }
    if (spec.capacity < 1) return InvalidArgument(where + ": capacity must be >= 1");
    for (const ParkingStation& other : map.stations_) {
      if (other.point == *p) {
        return InvalidArgument(where + ": point '" + spec.point + "' already holds station '" +
                               other.name + "'");
      }
    }
    map.stations_.push_back({spec.name, *p, spec.capacity});
  }

  // Shelves.
  names.clear();
  for (std::size_t i = 0; i < shelves_.size(); ++i) {
    const Shelf& shelf = shelves_[i];
    const std::string where = "shelf " + std::to_string(i) + " ('" + shelf.name + "')";
    if (shelf.name.empty()) return InvalidArgument(where + ": empty id");
    if (!names.insert(shelf.name).second) return InvalidArgument(where + ": duplicate id");
    if (!Finite(shelf.min) || !Finite(shelf.max) || !(shelf.min.x() < shelf.max.x()) ||
        !(shelf.min.y() < shelf.max.y())) {
      return InvalidArgument(where + ": min " + Fmt(shelf.min) + " must be below max " +
                             Fmt(shelf.max));
    }
    map.shelves_.push_back(shelf);
  }

  // Free spaces: each holds at least one point of the graph (where robots enter it).
  names.clear();
  for (std::size_t i = 0; i < free_spaces_.size(); ++i) {
    FreeSpace space = free_spaces_[i];
    const std::string where = "free space " + std::to_string(i) + " ('" + space.name + "')";
    if (space.name.empty()) return InvalidArgument(where + ": empty id");
    if (!names.insert(space.name).second) return InvalidArgument(where + ": duplicate id");
    Result<double> area = CheckPolygon(where, space.polygon, floor_);
    if (!area.ok()) return area.error();
    space.area = *area;
    space.points.clear();
    for (std::size_t p = 0; p < map.points_.size(); ++p) {
      if (space.Contains(map.points_[p].position)) space.points.push_back(static_cast<PointId>(p));
    }
    if (space.points.empty()) {
      return InvalidArgument(where + ": holds no point of the road graph, so no robot could enter it");
    }
    map.free_spaces_.push_back(std::move(space));
  }

  // Every service point reaches every other one.
  if (options.check_service_connectivity) {
    PointId first = kNoPoint;
    for (std::size_t i = 0; i < map.points_.size(); ++i) {
      if (IsServicePoint(map.points_[i].kind)) {
        first = static_cast<PointId>(i);
        break;
      }
    }
    if (first != kNoPoint) {
      const auto forward = Reach(map, first, true);
      const auto backward = Reach(map, first, false);
      const Point& f = map.point(first);
      for (std::size_t i = 0; i < map.points_.size(); ++i) {
        const Point& p = map.points_[i];
        if (!IsServicePoint(p.kind)) continue;
        const std::string desc = std::string(PointKindName(p.kind)) + " point '" + p.name + "'";
        const std::string fdesc = std::string(PointKindName(f.kind)) + " point '" + f.name + "'";
        if (!forward[i]) return InvalidArgument(desc + " cannot be reached from " + fdesc);
        if (!backward[i]) return InvalidArgument(fdesc + " cannot be reached from " + desc);
      }
    }
  }
  map.point_grid_ = PointGrid(map.points_);
  return map;
}

}  // namespace dispatch::engine
