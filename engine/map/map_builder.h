// Builds a WarehouseMap from parts named by string ids, then validates every invariant listed
// in warehouse_map.h. Build() never throws on bad input: it returns an Error whose message
// names the offending element (e.g. "path 12 (a -> b): unknown point 'b'").
//
// Used by the JSON reader, the MovingAI importer and the built-in floor generators.
// Not thread-safe; a builder is a short-lived local value.
#pragma once

#include <Eigen/Core>

#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "engine/common/result.h"
#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

struct MapBuildOptions {
  // Check that every pick/drop/park point reaches every other one. Importers of very large
  // grids may turn it off after they have ensured connectivity themselves.
  bool check_service_connectivity = true;
};

class MapBuilder {
 public:
  explicit MapBuilder(std::string name) : name_(std::move(name)) {}

  void SetFloor(const Eigen::Vector2d& min, const Eigen::Vector2d& max);
  void AddZone(std::string name, std::vector<Eigen::Vector2d> polygon);
  void AddRectZone(std::string name, const Eigen::Vector2d& min, const Eigen::Vector2d& max);
  // `zone` empty: the first zone that contains the point.
  void AddPoint(std::string name, const Eigen::Vector2d& position, PointKind kind,
                std::string zone = {});
  // `length` unset: the straight distance between the ends.
  void AddPath(std::string from, std::string to, std::optional<double> length = std::nullopt,
               double max_speed = 0.0, bool bidirectional = false);
  void AddIntersection(std::string name, std::vector<std::string> inner,
                       std::vector<std::string> approach);
  void AddStation(std::string name, std::string point, int capacity);
  void AddShelf(std::string name, const Eigen::Vector2d& min, const Eigen::Vector2d& max);
  // A free-space region (warehouse_map.h FreeSpace): a simple polygon on the floor holding at
  // least one point of the road graph.
  void AddFreeSpace(std::string name, std::vector<Eigen::Vector2d> polygon);

  bool HasPoint(const std::string& name) const;
  std::size_t point_count() const { return points_.size(); }

  Result<WarehouseMap> Build(const MapBuildOptions& options = {}) const;

 private:
  struct PointSpec {
    std::string name;
    Eigen::Vector2d position;
    PointKind kind;
    std::string zone;
  };
  struct PathSpec {
    std::string from, to;
    std::optional<double> length;
    double max_speed;
    bool bidirectional;
  };
  struct IntersectionSpec {
    std::string name;
    std::vector<std::string> inner, approach;
  };
  struct StationSpec {
    std::string name, point;
    int capacity;
  };

  std::string name_;
  std::optional<std::pair<Eigen::Vector2d, Eigen::Vector2d>> floor_;
  std::vector<Zone> zones_;
  std::vector<PointSpec> points_;
  std::vector<PathSpec> paths_;
  std::vector<IntersectionSpec> intersections_;
  std::vector<StationSpec> stations_;
  std::vector<Shelf> shelves_;
  std::vector<FreeSpace> free_spaces_;
  std::unordered_map<std::string, std::size_t> point_names_;
};

}  // namespace dispatch::engine
