#include "engine/io/map_json.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <optional>
#include <sstream>
#include <utility>
#include <vector>

#include "engine/common/text.h"
#include "engine/map/map_builder.h"
#include "formats/json_keys.h"

namespace dispatch::engine {
namespace {

using nlohmann::json;

std::string At(const std::string& where, std::string_view key) {
  std::string out = where;
  if (!out.empty()) out += '.';
  out += key;
  return out;
}

std::string Index(const std::string& where, std::size_t i) {
  return where + "[" + std::to_string(i) + "]";
}

Error TypeError(const std::string& where, std::string_view expected, const json& got) {
  return InvalidArgument(where + ": expected " + std::string(expected) + ", got " +
                         got.type_name());
}

// Rejects keys not in `allowed` (catches typos such as "lenght"); keys starting with "x-" are
// extensions and ignored.
Status CheckKeys(const json& obj, const std::string& where,
                 std::initializer_list<std::string_view> allowed) {
  for (const auto& item : obj.items()) {
    const std::string& key = item.key();
    if (key.rfind("x-", 0) == 0) continue;
    bool known = false;
    for (std::string_view a : allowed) known = known || key == a;
    if (!known) {
      return InvalidArgument((where.empty() ? std::string("top level") : where) +
                             ": unknown field '" + key + "'");
    }
  }
  return Ok{};
}

// The member `key` of `obj`, nullptr when absent and optional.
Result<const json*> Member(const json& obj, const std::string& where, std::string_view key,
                           bool required) {
  auto it = obj.find(key);
  if (it == obj.end()) {
    if (!required) return static_cast<const json*>(nullptr);
    return InvalidArgument((where.empty() ? std::string("top level") : where) +
                           ": missing required field '" + std::string(key) + "'");
  }
  return &*it;
}

Result<double> AsNumber(const json& v, const std::string& where) {
  if (!v.is_number()) return TypeError(where, "a number", v);
  return v.get<double>();
}

Result<std::string> AsId(const json& v, const std::string& where) {
  if (!v.is_string()) return TypeError(where, "a string", v);
  std::string s = v.get<std::string>();
  if (s.empty()) return InvalidArgument(where + ": must not be empty");
  return s;
}

Result<bool> AsBool(const json& v, const std::string& where) {
  if (!v.is_boolean()) return TypeError(where, "a boolean", v);
  return v.get<bool>();
}

Result<int> AsInt(const json& v, const std::string& where) {
  if (!v.is_number_integer()) return TypeError(where, "an integer", v);
  if (v.is_number_unsigned()) {
    auto u = v.get<std::uint64_t>();
    if (u > static_cast<std::uint64_t>(std::numeric_limits<int>::max())) {
      return InvalidArgument(where + ": " + std::to_string(u) + " is out of range");
    }
    return static_cast<int>(u);
  }
  auto i = v.get<std::int64_t>();
  if (i < std::numeric_limits<int>::min() || i > std::numeric_limits<int>::max()) {
    return InvalidArgument(where + ": " + std::to_string(i) + " is out of range");
  }
  return static_cast<int>(i);
}

Result<Eigen::Vector2d> AsVec2(const json& v, const std::string& where) {
  if (!v.is_array()) return TypeError(where, "an array [x, y]", v);
  if (v.size() != 2) {
    return InvalidArgument(where + ": expected an array [x, y] of 2 numbers, got " +
                           std::to_string(v.size()) + " elements");
  }
  Eigen::Vector2d out;
  for (std::size_t i = 0; i < 2; ++i) {
    auto n = AsNumber(v[i], Index(where, i));
    if (!n) return n.error();
    out[static_cast<Eigen::Index>(i)] = *n;
  }
  return out;
}

Result<const json*> ArrayMember(const json& obj, std::string_view key, bool required) {
  auto m = Member(obj, "", key, required);
  if (!m) return m.error();
  if (*m != nullptr && !(*m)->is_array()) return TypeError(std::string(key), "an array", **m);
  return *m;
}

Result<std::vector<std::string>> AsIdList(const json& v, const std::string& where) {
  if (!v.is_array()) return TypeError(where, "an array of point ids", v);
  std::vector<std::string> out;
  for (std::size_t i = 0; i < v.size(); ++i) {
    auto id = AsId(v[i], Index(where, i));
    if (!id) return id.error();
    out.push_back(std::move(id).value());
  }
  return out;
}

// Every element of the array `key` must be an object; calls fn(element, "key[i]").
template <class Fn>
Status ForEachObject(const json* array, std::string_view key, Fn&& fn) {
  if (array == nullptr) return Ok{};
  for (std::size_t i = 0; i < array->size(); ++i) {
    const json& e = (*array)[i];
    std::string where = Index(std::string(key), i);
    if (!e.is_object()) return TypeError(where, "an object", e);
    Status s = fn(e, where);
    if (!s) return s;
  }
  return Ok{};
}

Status ReadHeader(const json& doc) {
  auto format = Member(doc, "", "format", true);
  if (!format) return format.error();
  if (!(*format)->is_string()) return TypeError("format", "a string", **format);
  if ((*format)->get<std::string>() != kMapJsonFormat) {
    return InvalidArgument("format: expected \"" + std::string(kMapJsonFormat) + "\", got \"" +
                           (*format)->get<std::string>() + "\" (not a warehouse map file)");
  }
  auto version = Member(doc, "", "version", true);
  if (!version) return version.error();
  auto v = AsInt(**version, "version");
  if (!v) return v.error();
  if (*v != kMapJsonVersion) {
    return InvalidArgument("version: unsupported version " + std::to_string(*v) +
                           " (this reader supports version " + std::to_string(kMapJsonVersion) +
                           ")");
  }
  return CheckKeys(doc, "", {"format", "version", "name", "floor", "zones", "points", "paths",
                             "intersections", "stations", "shelves", "free_space"});
}

Status ReadFloor(const json& doc, MapBuilder& builder) {
  auto floor = Member(doc, "", "floor", true);
  if (!floor) return floor.error();
  const json& f = **floor;
  if (!f.is_object()) return TypeError("floor", "an object", f);
  if (Status s = CheckKeys(f, "floor", {"min", "max"}); !s) return s;
  auto min_m = Member(f, "floor", "min", true);
  if (!min_m) return min_m.error();
  auto max_m = Member(f, "floor", "max", true);
  if (!max_m) return max_m.error();
  auto min = AsVec2(**min_m, "floor.min");
  if (!min) return min.error();
  auto max = AsVec2(**max_m, "floor.max");
  if (!max) return max.error();
  if (!((*max).array() > (*min).array()).all()) {
    return InvalidArgument("floor: max must be greater than min in x and y");
  }
  builder.SetFloor(*min, *max);
  return Ok{};
}

// An element {"id", "polygon"} (a zone, a free space): its id and vertices.
Result<std::pair<std::string, std::vector<Eigen::Vector2d>>> ReadPolygonElement(
    const json& z, const std::string& where, const char* what) {
  if (Status s = CheckKeys(z, where, {"id", "polygon"}); !s) return s.error();
  auto id_m = Member(z, where, "id", true);
  if (!id_m) return id_m.error();
  auto id = AsId(**id_m, At(where, "id"));
  if (!id) return id.error();
  auto poly_m = Member(z, where, "polygon", true);
  if (!poly_m) return poly_m.error();
  const json& poly = **poly_m;
  std::string pw = At(where, "polygon");
  if (!poly.is_array()) return TypeError(pw, "an array of [x, y] vertices", poly);
  if (poly.size() < 3) {
    return InvalidArgument(pw + ": " + what + " '" + *id + "' needs at least 3 vertices, got " +
                           std::to_string(poly.size()));
  }
  std::vector<Eigen::Vector2d> vertices;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    auto v = AsVec2(poly[i], Index(pw, i));
    if (!v) return v.error();
    vertices.push_back(*v);
  }
  return std::make_pair(std::move(id).value(), std::move(vertices));
}

Status ReadZone(const json& z, const std::string& where, MapBuilder& builder) {
  auto zone = ReadPolygonElement(z, where, "zone");
  if (!zone) return zone.error();
  builder.AddZone(std::move(zone->first), std::move(zone->second));
  return Ok{};
}

Status ReadFreeSpace(const json& z, const std::string& where, MapBuilder& builder) {
  auto space = ReadPolygonElement(z, where, "free space");
  if (!space) return space.error();
  builder.AddFreeSpace(std::move(space->first), std::move(space->second));
  return Ok{};
}

Status ReadPoint(const json& p, const std::string& where, MapBuilder& builder) {
  if (Status s = CheckKeys(p, where, {"id", "x", "y", "kind", "zone"}); !s) return s;
  Result<const json*> id_m = Member(p, where, "id", true);
  if (!id_m) return id_m.error();
  auto id = AsId(**id_m, At(where, "id"));
  if (!id) return id.error();
  double xy[2] = {0, 0};
  const char* axes[2] = {"x", "y"};
  for (int i = 0; i < 2; ++i) {
    auto m = Member(p, where, axes[i], true);
    if (!m) return m.error();
    auto n = AsNumber(**m, At(where, axes[i]));
    if (!n) return n.error();
    xy[i] = *n;
  }
  auto kind_m = Member(p, where, "kind", true);
  if (!kind_m) return kind_m.error();
  if (!(*kind_m)->is_string()) return TypeError(At(where, "kind"), "a string", **kind_m);
  std::string kind_name = (*kind_m)->get<std::string>();
  std::optional<PointKind> kind = ParsePointKind(kind_name);
  if (!kind) {
    return InvalidArgument(At(where, "kind") + ": unknown point kind '" + kind_name +
                           "' for point '" + *id +
                           "' (expected lane, intersection, pick, drop, park or charge)");
  }
  std::string zone;
  auto zone_m = Member(p, where, "zone", false);
  if (!zone_m) return zone_m.error();
  if (*zone_m != nullptr) {
    auto z = AsId(**zone_m, At(where, "zone"));
    if (!z) return z.error();
    zone = std::move(z).value();
  }
  builder.AddPoint(std::move(id).value(), Eigen::Vector2d(xy[0], xy[1]), *kind, std::move(zone));
  return Ok{};
}

Status ReadPath(const json& p, const std::string& where, MapBuilder& builder) {
  if (Status s = CheckKeys(p, where, {"from", "to", "length", "max_speed", "bidirectional"}); !s) {
    return s;
  }
  std::string ends[2];
  const char* keys[2] = {"from", "to"};
  for (int i = 0; i < 2; ++i) {
    auto m = Member(p, where, keys[i], true);
    if (!m) return m.error();
    auto id = AsId(**m, At(where, keys[i]));
    if (!id) return id.error();
    ends[i] = std::move(id).value();
  }
  std::optional<double> length;
  auto len_m = Member(p, where, "length", false);
  if (!len_m) return len_m.error();
  if (*len_m != nullptr) {
    auto n = AsNumber(**len_m, At(where, "length"));
    if (!n) return n.error();
    if (!(*n > 0.0)) {
      return InvalidArgument(At(where, "length") + ": path " + ends[0] + " -> " + ends[1] +
                             " has non-positive length " + (**len_m).dump());
    }
    length = *n;
  }
  double max_speed = 0.0;
  auto speed_m = Member(p, where, "max_speed", false);
  if (!speed_m) return speed_m.error();
  if (*speed_m != nullptr) {
    auto n = AsNumber(**speed_m, At(where, "max_speed"));
    if (!n) return n.error();
    if (*n < 0.0) {
      return InvalidArgument(At(where, "max_speed") + ": path " + ends[0] + " -> " + ends[1] +
                             " has negative max_speed " + (**speed_m).dump());
    }
    max_speed = *n;
  }
  bool bidirectional = false;
  auto bidi_m = Member(p, where, "bidirectional", false);
  if (!bidi_m) return bidi_m.error();
  if (*bidi_m != nullptr) {
    auto b = AsBool(**bidi_m, At(where, "bidirectional"));
    if (!b) return b.error();
    bidirectional = *b;
  }
  builder.AddPath(std::move(ends[0]), std::move(ends[1]), length, max_speed, bidirectional);
  return Ok{};
}

Status ReadIntersection(const json& e, const std::string& where, MapBuilder& builder) {
  if (Status s = CheckKeys(e, where, {"id", "inner", "approach"}); !s) return s;
  auto id_m = Member(e, where, "id", true);
  if (!id_m) return id_m.error();
  auto id = AsId(**id_m, At(where, "id"));
  if (!id) return id.error();
  std::vector<std::string> lists[2];
  const char* keys[2] = {"inner", "approach"};
  for (int i = 0; i < 2; ++i) {
    auto m = Member(e, where, keys[i], true);
    if (!m) return m.error();
    auto ids = AsIdList(**m, At(where, keys[i]));
    if (!ids) return ids.error();
    lists[i] = std::move(ids).value();
  }
  builder.AddIntersection(std::move(id).value(), std::move(lists[0]), std::move(lists[1]));
  return Ok{};
}

Status ReadStation(const json& e, const std::string& where, MapBuilder& builder) {
  if (Status s = CheckKeys(e, where, {"id", "point", "capacity"}); !s) return s;
  auto id_m = Member(e, where, "id", true);
  if (!id_m) return id_m.error();
  auto id = AsId(**id_m, At(where, "id"));
  if (!id) return id.error();
  auto point_m = Member(e, where, "point", true);
  if (!point_m) return point_m.error();
  auto point = AsId(**point_m, At(where, "point"));
  if (!point) return point.error();
  auto cap_m = Member(e, where, "capacity", true);
  if (!cap_m) return cap_m.error();
  auto cap = AsInt(**cap_m, At(where, "capacity"));
  if (!cap) return cap.error();
  if (*cap < 1) {
    return InvalidArgument(At(where, "capacity") + ": station '" + *id +
                           "' needs capacity >= 1, got " + std::to_string(*cap));
  }
  builder.AddStation(std::move(id).value(), std::move(point).value(), *cap);
  return Ok{};
}

Status ReadShelf(const json& e, const std::string& where, MapBuilder& builder) {
  if (Status s = CheckKeys(e, where, {"id", "min", "max"}); !s) return s;
  auto id_m = Member(e, where, "id", true);
  if (!id_m) return id_m.error();
  auto id = AsId(**id_m, At(where, "id"));
  if (!id) return id.error();
  Eigen::Vector2d corners[2];
  const char* keys[2] = {"min", "max"};
  for (int i = 0; i < 2; ++i) {
    auto m = Member(e, where, keys[i], true);
    if (!m) return m.error();
    auto v = AsVec2(**m, At(where, keys[i]));
    if (!v) return v.error();
    corners[i] = *v;
  }
  if (!(corners[1].array() > corners[0].array()).all()) {
    return InvalidArgument(where + ": shelf '" + *id +
                           "' needs max greater than min in x and y");
  }
  builder.AddShelf(std::move(id).value(), corners[0], corners[1]);
  return Ok{};
}

// "line 3, column 13 (byte 44): syntax error ...". The line and column are computed from the
// byte offset because nlohmann's own column is off after a lookahead across a newline.
std::string DescribeParseError(std::string_view text, const json::parse_error& e) {
  const std::size_t last = std::min<std::size_t>(e.byte > 0 ? e.byte - 1 : 0, text.size());
  std::size_t line = 1;
  std::size_t line_start = 0;
  for (std::size_t i = 0; i < last; ++i) {
    if (text[i] == '\n') {
      ++line;
      line_start = i + 1;
    }
  }
  std::string reason = e.what();
  // nlohmann: "[json.exception.parse_error.101] parse error at line 3, column 0: <reason>".
  if (auto colon = reason.find(": "); colon != std::string::npos) reason.erase(0, colon + 2);
  return "line " + std::to_string(line) + ", column " + std::to_string(last - line_start + 1) +
         " (byte " + std::to_string(e.byte) + "): " + reason;
}

}  // namespace

Result<WarehouseMap> ParseMapJson(std::string_view text) {
  json doc;
  std::optional<std::string> key;
  try {
    doc = formats::ParseNotingDuplicateKey(text, &key);
  } catch (const json::parse_error& e) {
    return InvalidArgument("not valid JSON: " + DescribeParseError(text, e));
  } catch (const json::exception& e) {  // e.g. a number too large for a double (found by fuzz_map_json)
    return InvalidArgument(std::string("not valid JSON: ") + e.what());
  }
  if (!doc.is_object()) return TypeError("top level", "an object", doc);
  if (key) {
    return InvalidArgument("the key '" + Clipped(*key) + "' appears twice in one object (which one counts?)");
  }
  if (Status s = ReadHeader(doc); !s) return s.error();

  auto name_m = Member(doc, "", "name", true);
  if (!name_m) return name_m.error();
  auto name = AsId(**name_m, "name");
  if (!name) return name.error();
  MapBuilder builder(std::move(name).value());
  if (Status s = ReadFloor(doc, builder); !s) return s.error();

  struct Section {
    std::string_view key;
    bool required;
    Status (*read)(const json&, const std::string&, MapBuilder&);
  };
  const Section sections[] = {
      {"zones", true, ReadZone},          {"points", true, ReadPoint},
      {"paths", true, ReadPath},          {"intersections", false, ReadIntersection},
      {"stations", false, ReadStation},   {"shelves", false, ReadShelf},
      {"free_space", false, ReadFreeSpace},
  };
  for (const Section& section : sections) {
    auto array = ArrayMember(doc, section.key, section.required);
    if (!array) return array.error();
    Status s = ForEachObject(*array, section.key, [&](const json& e, const std::string& where) {
      return section.read(e, where, builder);
    });
    if (!s) return s.error();
  }
  return builder.Build();
}

Result<WarehouseMap> LoadMapJsonFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return IoError(path + ": cannot open map file");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) return IoError(path + ": read error");
  Result<WarehouseMap> map = ParseMapJson(buffer.str());
  if (!map) return Error{map.error().code, path + ": " + map.error().message};
  return map;
}

}  // namespace dispatch::engine
