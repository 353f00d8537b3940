// The warehouse road graph (SPEC §2): points, one-way paths and bidirectional single lanes,
// intersections (inner region I_w + approach points O_w, Chu2024 §3.3), zones with areas
// (Chu2024 eq. (7) S_p), parking stations and shelves.
//
// Invariants (checked by MapBuilder::Build, so every WarehouseMap satisfies them):
//  - point, zone, intersection, station and shelf names are unique and non-empty;
//  - every path joins two distinct existing points and has a finite length > 0 that is not
//    shorter than the straight distance between its ends;
//  - every point lies inside the zone it names (or in some zone, when it names none);
//  - every zone is a simple polygon with a positive area inside the floor; intersections name
//    existing points, each at most once; no point is inner to two intersections, and approach
//    points are inner to none; stations sit on distinct points of kind park or charge, with
//    capacity >= 1;
//  - every pick, drop and park point reaches every other one (strong connectivity of service
//    points), so a served order never hits a disconnected drop.
// A WarehouseMap is immutable once built: safe to share between threads for reading.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "engine/common/result.h"
#include "engine/map/point_grid.h"

namespace dispatch::engine {

using PointId = std::int32_t;
using ArcId = std::int32_t;
using ZoneId = std::int32_t;
inline constexpr PointId kNoPoint = -1;

enum class PointKind { kLane, kIntersection, kPick, kDrop, kPark, kCharge };
const char* PointKindName(PointKind kind);
std::optional<PointKind> ParsePointKind(const std::string& name);
// Pick, drop, park and charge points are where robots stop to serve; lanes and intersections
// are only driven through.
bool IsServicePoint(PointKind kind);

struct Point {
  std::string name;
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  PointKind kind = PointKind::kLane;
  ZoneId zone = 0;
};

// A path as written in a map file. A one-way path yields one arc from -> to; a bidirectional
// single lane (Wang2019 §3.3) yields two arcs that share the same physical lane.
struct Path {
  PointId from = kNoPoint;
  PointId to = kNoPoint;
  double length = 0.0;     // metres
  double max_speed = 0.0;  // m/s; 0 = no limit of its own (robot speed applies)
  bool bidirectional = false;
};

// A directed, drivable arc derived from a Path. `reverse_arc` is the opposite arc of the same
// single lane (or -1 for one-way paths). Robots move continuously along arcs.
struct Arc {
  PointId from = kNoPoint;
  PointId to = kNoPoint;
  double length = 0.0;
  double max_speed = 0.0;
  std::int32_t path = -1;
  ArcId reverse_arc = -1;
  bool single_lane() const { return reverse_arc >= 0; }
};

// Whether a simple polygon (either orientation) holds p; its boundary counts as inside.
bool PolygonContains(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& p);

struct Zone {
  std::string name;
  std::vector<Eigen::Vector2d> polygon;  // simple polygon, either orientation
  double area = 0.0;                     // S_p, m^2 (derived)
  bool Contains(const Eigen::Vector2d& p) const { return PolygonContains(polygon, p); }
};

// A free-space region (issue 17 §3): a narrow area where a robot that can (four-wheel steer)
// is planned over continuous poses (engine/motion, BIT2024 step 6) instead of along the road
// graph; shelves inside it are obstacles. The road graph's points inside it (boundary
// included) are where the two meet: a robot enters and leaves the region there.
struct FreeSpace {
  std::string name;
  std::vector<Eigen::Vector2d> polygon;  // simple polygon, either orientation
  double area = 0.0;                     // m^2 (derived)
  std::vector<PointId> points;           // derived: the graph's points in it, ascending
  bool Contains(const Eigen::Vector2d& p) const { return PolygonContains(polygon, p); }
};

struct Intersection {
  std::string name;
  std::vector<PointId> inner;     // I_w
  std::vector<PointId> approach;  // O_w: where a robot without a grant stops
};

struct ParkingStation {
  std::string name;
  PointId point = kNoPoint;
  int capacity = 1;
};

struct Shelf {
  std::string name;
  Eigen::Vector2d min = Eigen::Vector2d::Zero();
  Eigen::Vector2d max = Eigen::Vector2d::Zero();
};

// A robot's continuous position on the graph: `offset` metres along `arc` from its start.
struct ArcPosition {
  ArcId arc = -1;
  double offset = 0.0;
};

class WarehouseMap {
 public:
  const std::string& name() const { return name_; }
  const Eigen::Vector2d& floor_min() const { return floor_min_; }
  const Eigen::Vector2d& floor_max() const { return floor_max_; }

  const std::vector<Point>& points() const { return points_; }
  const std::vector<Path>& paths() const { return paths_; }
  const std::vector<Arc>& arcs() const { return arcs_; }
  const std::vector<Zone>& zones() const { return zones_; }
  const std::vector<Intersection>& intersections() const { return intersections_; }
  const std::vector<ParkingStation>& stations() const { return stations_; }
  const std::vector<Shelf>& shelves() const { return shelves_; }
  const std::vector<FreeSpace>& free_spaces() const { return free_spaces_; }

  std::size_t point_count() const { return points_.size(); }
  const Point& point(PointId id) const { return points_.at(static_cast<std::size_t>(id)); }
  const Arc& arc(ArcId id) const { return arcs_.at(static_cast<std::size_t>(id)); }
  const std::vector<ArcId>& out_arcs(PointId id) const {
    return out_arcs_.at(static_cast<std::size_t>(id));
  }
  const std::vector<ArcId>& in_arcs(PointId id) const {
    return in_arcs_.at(static_cast<std::size_t>(id));
  }

  std::optional<PointId> FindPoint(const std::string& name) const;
  std::optional<ZoneId> FindZone(const std::string& name) const;
  // The arc from -> to, if one exists.
  std::optional<ArcId> FindArc(PointId from, PointId to) const;
  // Intersection whose inner region contains the point, or -1.
  int IntersectionOf(PointId id) const { return intersection_of_.at(static_cast<std::size_t>(id)); }

  // (arc, offset) -> (x, y). Offsets are clamped to [0, length].
  Eigen::Vector2d PositionOf(const ArcPosition& pos) const;
  // (x, y) -> the nearest (arc, offset), with its distance; error on a map without arcs.
  Result<ArcPosition> NearestArcPosition(const Eigen::Vector2d& xy, double* distance = nullptr) const;
  // The nearest point (optionally of one kind) to (x, y); kNoPoint if none. The lowest id
  // among points at the same distance. Without a kind: a grid lookup (point_grid.h).
  PointId NearestPoint(const Eigen::Vector2d& xy, std::optional<PointKind> kind = std::nullopt,
                       double* distance = nullptr) const;
  // NearestPoint(xy), trying `hint` first, then the points one arc from it (a robot's last
  // point and where it drives: most reports are near one of them).
  PointId NearestPointFrom(const Eigen::Vector2d& xy, PointId hint) const;

 private:
  friend class MapBuilder;
  std::string name_;
  Eigen::Vector2d floor_min_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d floor_max_ = Eigen::Vector2d::Zero();
  std::vector<Point> points_;
  std::vector<Path> paths_;
  std::vector<Arc> arcs_;
  std::vector<Zone> zones_;
  std::vector<Intersection> intersections_;
  std::vector<ParkingStation> stations_;
  std::vector<Shelf> shelves_;
  std::vector<FreeSpace> free_spaces_;
  std::vector<std::vector<ArcId>> out_arcs_;
  std::vector<std::vector<ArcId>> in_arcs_;
  std::vector<int> intersection_of_;
  std::unordered_map<std::string, PointId> point_index_;
  std::unordered_map<std::string, ZoneId> zone_index_;
  PointGrid point_grid_;  // built by MapBuilder once the points are final
};

}  // namespace dispatch::engine
