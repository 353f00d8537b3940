// WriteMapJson: the canonical text of a map (map_format.md "Canonical output"); the reader is
// in map_json.cpp.
#include <nlohmann/json.hpp>

#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "engine/io/map_json.h"

namespace dispatch::engine {
namespace {

using nlohmann::ordered_json;

// Compact one-line text of a number pair, e.g. [1.5,2.0].
ordered_json Vec2Json(const Eigen::Vector2d& v) { return ordered_json::array({v.x(), v.y()}); }

void WriteArray(std::ostringstream& out, std::string_view key,
                const std::vector<ordered_json>& elements, bool last) {
  out << "  \"" << key << "\": [";
  for (std::size_t i = 0; i < elements.size(); ++i) {
    out << (i == 0 ? "\n    " : ",\n    ") << elements[i].dump();
  }
  out << (elements.empty() ? "]" : "\n  ]") << (last ? "\n" : ",\n");
}

}  // namespace

std::string WriteMapJson(const WarehouseMap& map) {
  std::ostringstream out;
  out << "{\n";
  out << "  \"format\": " << ordered_json(kMapJsonFormat).dump() << ",\n";
  out << "  \"version\": " << kMapJsonVersion << ",\n";
  out << "  \"name\": " << ordered_json(map.name()).dump() << ",\n";
  ordered_json floor;
  floor["min"] = Vec2Json(map.floor_min());
  floor["max"] = Vec2Json(map.floor_max());
  out << "  \"floor\": " << floor.dump() << ",\n";

  auto polygon_element = [](const std::string& name, const std::vector<Eigen::Vector2d>& polygon) {
    ordered_json e;
    e["id"] = name;
    e["polygon"] = ordered_json::array();
    for (const auto& v : polygon) e["polygon"].push_back(Vec2Json(v));
    return e;
  };
  std::vector<ordered_json> items;
  for (const Zone& z : map.zones()) items.push_back(polygon_element(z.name, z.polygon));
  WriteArray(out, "zones", items, false);

  items.clear();
  for (const Point& p : map.points()) {
    ordered_json e;
    e["id"] = p.name;
    e["x"] = p.position.x();
    e["y"] = p.position.y();
    e["kind"] = PointKindName(p.kind);
    if (p.zone >= 0 && static_cast<std::size_t>(p.zone) < map.zones().size()) {
      e["zone"] = map.zones()[static_cast<std::size_t>(p.zone)].name;
    }
    items.push_back(std::move(e));
  }
  WriteArray(out, "points", items, false);

  items.clear();
  for (const Path& p : map.paths()) {
    ordered_json e;
    e["from"] = map.point(p.from).name;
    e["to"] = map.point(p.to).name;
    e["length"] = p.length;
    if (p.max_speed > 0.0) e["max_speed"] = p.max_speed;
    e["bidirectional"] = p.bidirectional;
    items.push_back(std::move(e));
  }
  WriteArray(out, "paths", items, false);

  items.clear();
  for (const Intersection& x : map.intersections()) {
    ordered_json e;
    e["id"] = x.name;
    e["inner"] = ordered_json::array();
    for (PointId id : x.inner) e["inner"].push_back(map.point(id).name);
    e["approach"] = ordered_json::array();
    for (PointId id : x.approach) e["approach"].push_back(map.point(id).name);
    items.push_back(std::move(e));
  }
  WriteArray(out, "intersections", items, false);

  items.clear();
  for (const ParkingStation& s : map.stations()) {
    ordered_json e;
    e["id"] = s.name;
    e["point"] = map.point(s.point).name;
    e["capacity"] = s.capacity;
    items.push_back(std::move(e));
  }
  WriteArray(out, "stations", items, false);

  items.clear();
  for (const Shelf& s : map.shelves()) {
    ordered_json e;
    e["id"] = s.name;
    e["min"] = Vec2Json(s.min);
    e["max"] = Vec2Json(s.max);
    items.push_back(std::move(e));
  }
  WriteArray(out, "shelves", items, map.free_spaces().empty());
  if (!map.free_spaces().empty()) {  // the key only where there are some: older files stay as they were
    items.clear();
    for (const FreeSpace& f : map.free_spaces()) items.push_back(polygon_element(f.name, f.polygon));
    WriteArray(out, "free_space", items, true);
  }
  out << "}\n";
  return out.str();
}

}  // namespace dispatch::engine
