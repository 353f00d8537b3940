#include "engine/io/map_json.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "engine/map/map_builder.h"

namespace dispatch::engine {
namespace {

using nlohmann::json;

// A small floor with every element: a polygon zone and a rectangle zone, all point kinds,
// one-way paths (one with a length and a speed limit), bidirectional single lanes, an
// intersection, a station and a shelf.
WarehouseMap SampleMap() {
  MapBuilder b("sample & co");
  b.SetFloor({0, 0}, {20, 8});
  b.AddZone("A", {{0, 0}, {10, 0}, {10, 6}, {5, 8}, {0, 6}});
  b.AddRectZone("B", {10, 0}, {20, 8});
  b.AddPoint("a", {1, 1}, PointKind::kLane, "A");
  b.AddPoint("b", {5, 1}, PointKind::kIntersection, "A");
  b.AddPoint("c", {9, 1}, PointKind::kLane);  // zone from position
  b.AddPoint("d", {5, 4}, PointKind::kPick, "A");
  b.AddPoint("e", {12, 2}, PointKind::kDrop, "B");
  b.AddPoint("f", {15, 2}, PointKind::kPark, "B");
  b.AddPoint("g", {18, 5.25}, PointKind::kCharge, "B");
  b.AddPath("a", "b", std::nullopt, 0.0, true);
  b.AddPath("b", "c", std::nullopt, 0.0, true);
  b.AddPath("b", "d", std::nullopt, 0.0, true);
  b.AddPath("c", "e", 3.5);
  b.AddPath("e", "f", std::nullopt, 1.5);
  b.AddPath("f", "g", std::nullopt, 0.0, true);
  b.AddPath("g", "c", 12.0);
  b.AddIntersection("X1", {"b"}, {"a", "c", "d"});
  b.AddStation("S1", "f", 2);
  b.AddShelf("sh1", {2, 5}, {4, 5.5});
  Result<WarehouseMap> map = b.Build();
  if (!map) ADD_FAILURE() << map.error().message;
  return std::move(map).value();
}

// The sample map as a mutable JSON document, for the error tests.
json SampleDoc() { return json::parse(WriteMapJson(SampleMap())); }

std::string ParseError(const json& doc) {
  Result<WarehouseMap> map = ParseMapJson(doc.dump());
  if (map) return "(parsed without error)";
  EXPECT_EQ(map.error().code, ErrorCode::kInvalidArgument);
  return map.error().message;
}

std::string ParseTextError(const std::string& text) {
  Result<WarehouseMap> map = ParseMapJson(text);
  return map ? "(parsed without error)" : map.error().message;
}

TEST(MapJsonTest, RoundTripGivesIdenticalTextAndEqualStructure) {
  const WarehouseMap m = SampleMap();
  const std::string text = WriteMapJson(m);
  Result<WarehouseMap> parsed = ParseMapJson(text);
  ASSERT_TRUE(parsed.ok()) << parsed.error().message;
  const WarehouseMap& p = *parsed;
  EXPECT_EQ(WriteMapJson(p), text);

  EXPECT_EQ(p.name(), m.name());
  EXPECT_EQ(p.floor_min(), m.floor_min());
  EXPECT_EQ(p.floor_max(), m.floor_max());
  ASSERT_EQ(p.zones().size(), m.zones().size());
  for (std::size_t i = 0; i < m.zones().size(); ++i) {
    EXPECT_EQ(p.zones()[i].name, m.zones()[i].name);
    EXPECT_EQ(p.zones()[i].polygon, m.zones()[i].polygon);
    EXPECT_DOUBLE_EQ(p.zones()[i].area, m.zones()[i].area);
  }
  EXPECT_DOUBLE_EQ(p.zones()[0].area, 70.0);  // 60 + triangle 10*2/2
  ASSERT_EQ(p.points().size(), m.points().size());
  for (std::size_t i = 0; i < m.points().size(); ++i) {
    EXPECT_EQ(p.points()[i].name, m.points()[i].name);
    EXPECT_EQ(p.points()[i].position, m.points()[i].position);
    EXPECT_EQ(p.points()[i].kind, m.points()[i].kind);
    EXPECT_EQ(p.points()[i].zone, m.points()[i].zone);
  }
  ASSERT_EQ(p.paths().size(), m.paths().size());
  for (std::size_t i = 0; i < m.paths().size(); ++i) {
    EXPECT_EQ(p.paths()[i].from, m.paths()[i].from);
    EXPECT_EQ(p.paths()[i].to, m.paths()[i].to);
    EXPECT_DOUBLE_EQ(p.paths()[i].length, m.paths()[i].length);
    EXPECT_DOUBLE_EQ(p.paths()[i].max_speed, m.paths()[i].max_speed);
    EXPECT_EQ(p.paths()[i].bidirectional, m.paths()[i].bidirectional);
  }
  EXPECT_EQ(p.arcs().size(), 11u);  // 7 paths, 4 of them bidirectional
  ASSERT_EQ(p.intersections().size(), 1u);
  EXPECT_EQ(p.intersections()[0].name, "X1");
  EXPECT_EQ(p.intersections()[0].inner, m.intersections()[0].inner);
  EXPECT_EQ(p.intersections()[0].approach, m.intersections()[0].approach);
  ASSERT_EQ(p.stations().size(), 1u);
  EXPECT_EQ(p.stations()[0].name, "S1");
  EXPECT_EQ(p.stations()[0].point, *p.FindPoint("f"));
  EXPECT_EQ(p.stations()[0].capacity, 2);
  ASSERT_EQ(p.shelves().size(), 1u);
  EXPECT_EQ(p.shelves()[0].name, "sh1");
  EXPECT_EQ(p.shelves()[0].min, Eigen::Vector2d(2, 5));
  EXPECT_EQ(p.shelves()[0].max, Eigen::Vector2d(4, 5.5));
  EXPECT_EQ(p.point(*p.FindPoint("c")).zone, *p.FindZone("A"));
}

// Free-space regions (issue 17 §3): optional, read and written back, the graph's points in
// them derived; each must hold a point and be a proper polygon on the floor.
TEST(MapJsonTest, FreeSpacesRoundTripAndAreValidated) {
  EXPECT_EQ(WriteMapJson(SampleMap()).find("free_space"), std::string::npos);  // only when some
  json doc = SampleDoc();
  doc["free_space"] = json::array({json{{"id", "F1"}, {"polygon", {{0, 0}, {6, 0}, {6, 3}, {0, 3}}}}});
  Result<WarehouseMap> map = ParseMapJson(doc.dump());
  ASSERT_TRUE(map.ok()) << map.error().message;
  ASSERT_EQ(map->free_spaces().size(), 1u);
  const FreeSpace& f = map->free_spaces()[0];
  EXPECT_EQ(f.name, "F1");
  EXPECT_DOUBLE_EQ(f.area, 18.0);
  EXPECT_EQ(f.points, (std::vector<PointId>{*map->FindPoint("a"), *map->FindPoint("b")}));
  const std::string text = WriteMapJson(*map);
  EXPECT_NE(text.find("\n  \"free_space\": [\n    {\"id\":\"F1\",\"polygon\":[[0.0,0.0],[6.0,0.0]"),
            std::string::npos) << text;
  Result<WarehouseMap> again = ParseMapJson(text);
  ASSERT_TRUE(again.ok()) << again.error().message;
  EXPECT_EQ(WriteMapJson(*again), text);

  auto with = [](json space) {
    json d = SampleDoc();
    d["free_space"] = json::array({std::move(space)});
    return d;
  };
  EXPECT_EQ(ParseError(with({{"id", "F1"}, {"polygon", {{0, 0}, {6, 0}}}})),
            "free_space[0].polygon: free space 'F1' needs at least 3 vertices, got 2");
  EXPECT_EQ(ParseError(with({{"id", "F2"}, {"polygon", {{11, 6}, {13, 6}, {13, 7}}}})),
            "free space 0 ('F2'): holds no point of the road graph, so no robot could enter it");
  EXPECT_EQ(ParseError(with({{"id", "F3"}, {"polygon", {{0, 0}, {6, 0}, {6, 30}}}})),
            "free space 0 ('F3'): vertex (6, 30) lies outside the floor");
  EXPECT_EQ(ParseError(with({{"id", "F4"}, {"polygon", {{0, 0}, {6, 3}, {6, 0}, {0, 2}}}})),
            "free space 0 ('F4'): polygon crosses itself, so its area is undefined");
  EXPECT_EQ(ParseError(with({{"id", "F5"}, {"polgon", {{0, 0}, {6, 0}, {6, 3}}}})),
            "free_space[0]: unknown field 'polgon'");
  json twice = SampleDoc();
  twice["free_space"] = json::array({json{{"id", "F"}, {"polygon", {{0, 0}, {6, 0}, {6, 3}}}},
                                     json{{"id", "F"}, {"polygon", {{0, 0}, {6, 0}, {6, 3}}}}});
  EXPECT_EQ(ParseError(twice), "free space 1 ('F'): duplicate id");
}

TEST(MapJsonTest, WriterIsCanonical) {
  const std::string text = WriteMapJson(SampleMap());
  EXPECT_EQ(text.rfind("{\n  \"format\": \"warehouse-map\",\n  \"version\": 1,\n", 0), 0u);
  EXPECT_NE(text.find("\n    {\"id\":\"a\",\"x\":1.0,\"y\":1.0,\"kind\":\"lane\",\"zone\":\"A\"}"),
            std::string::npos)
      << text;
  EXPECT_EQ(text.back(), '\n');
}

// Issue 18 §3: a key named twice in one object is refused (which one would count?), at any
// depth; the same key in two objects is fine.
TEST(MapJsonTest, AKeyTwiceInOneObjectIsRefused) {
  const std::string text = R"({
    "format": "warehouse-map", "version": 1, "name": "tiny",
    "floor": {"min": [0, 0], "max": [10, 10]},
    "zones": [{"id": "z", "polygon": [[0, 0], [10, 0], [10, 10], [0, 10]]}],
    "points": [{"id": "p", "x": 1, "y": 1, "kind": "pick"},
               {"id": "q", "x": 4, "y": 5, "kind": "drop", "kind": "pick"}],
    "paths": [{"from": "p", "to": "q", "bidirectional": true}]
  })";
  Result<WarehouseMap> map = ParseMapJson(text);
  ASSERT_FALSE(map.ok());
  EXPECT_NE(map.error().message.find("the key 'kind' appears twice"), std::string::npos) << map.error().message;
}

TEST(MapJsonTest, OptionalFieldsTakeTheirDefaults) {
  const std::string text = R"({
    "format": "warehouse-map", "version": 1, "name": "tiny",
    "floor": {"min": [0, 0], "max": [10, 10]},
    "zones": [{"id": "z", "polygon": [[0, 0], [10, 0], [10, 10], [0, 10]]}],
    "points": [{"id": "p", "x": 1, "y": 1, "kind": "pick"},
               {"id": "q", "x": 4, "y": 5, "kind": "drop"}],
    "paths": [{"from": "p", "to": "q", "bidirectional": true}],
    "x-editor": {"anything": "goes"}
  })";
  Result<WarehouseMap> map = ParseMapJson(text);
  ASSERT_TRUE(map.ok()) << map.error().message;
  ASSERT_EQ(map->paths().size(), 1u);
  EXPECT_DOUBLE_EQ(map->paths()[0].length, 5.0);  // straight distance
  EXPECT_DOUBLE_EQ(map->paths()[0].max_speed, 0.0);
  EXPECT_TRUE(map->paths()[0].bidirectional);
  EXPECT_EQ(map->point(0).zone, 0);
  EXPECT_TRUE(map->intersections().empty());
  EXPECT_TRUE(map->stations().empty());
  EXPECT_TRUE(map->shelves().empty());
}

TEST(MapJsonTest, OneWayIsTheDefault) {
  json doc = SampleDoc();
  doc["paths"][0].erase("bidirectional");
  // a -> b one-way only: a can no longer be reached, but it is a lane point, so it is legal.
  Result<WarehouseMap> map = ParseMapJson(doc.dump());
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_FALSE(map->paths()[0].bidirectional);
}

std::string ReadSource(const std::string& relative) {
  std::ifstream in(std::string(DISPATCH_SOURCE_DIR) + "/" + relative);
  EXPECT_TRUE(in.good()) << relative;
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(MapJsonTest, DocumentedExampleLoads) {
  const std::string doc = ReadSource("engine/io/map_format.md");
  const std::size_t begin = doc.find("```json\n");
  ASSERT_NE(begin, std::string::npos);
  const std::size_t end = doc.find("```", begin + 8);
  Result<WarehouseMap> map = ParseMapJson(doc.substr(begin + 8, end - begin - 8));
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(map->name(), "example");
  EXPECT_EQ(map->point_count(), 6u);
  EXPECT_EQ(map->arcs().size(), 7u);
  EXPECT_EQ(map->intersections().size(), 1u);
  EXPECT_EQ(map->stations().size(), 1u);
  EXPECT_EQ(map->shelves().size(), 1u);
}

TEST(MapJsonTest, SchemaMatchesTheReader) {
  const json schema = json::parse(ReadSource("engine/io/map.schema.json"));
  EXPECT_EQ(schema["properties"]["format"]["const"], "warehouse-map");
  EXPECT_EQ(schema["properties"]["version"]["const"], kMapJsonVersion);
  for (const auto& kind : schema["$defs"]["point"]["properties"]["kind"]["enum"]) {
    EXPECT_TRUE(ParsePointKind(kind.get<std::string>()).has_value()) << kind;
  }
  EXPECT_EQ(schema["$defs"]["point"]["properties"]["kind"]["enum"].size(), 6u);
}

TEST(MapJsonTest, FileRoundTripAndMissingFile) {
  const std::string path = ::testing::TempDir() + "map_json_test_sample.json";
  {
    std::ofstream out(path);
    out << WriteMapJson(SampleMap());
  }
  Result<WarehouseMap> map = LoadMapJsonFile(path);
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(map->point_count(), 7u);
  std::remove(path.c_str());

  Result<WarehouseMap> missing = LoadMapJsonFile(path);
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().code, ErrorCode::kIoError);
  EXPECT_NE(missing.error().message.find(path), std::string::npos);
}

TEST(MapJsonTest, FileErrorsNameThePath) {
  const std::string path = ::testing::TempDir() + "map_json_test_bad.json";
  {
    std::ofstream out(path);
    out << "[]";
  }
  Result<WarehouseMap> map = LoadMapJsonFile(path);
  std::remove(path.c_str());
  ASSERT_FALSE(map.ok());
  EXPECT_EQ(map.error().message, path + ": top level: expected an object, got array");
}

// --- One test per reader error class -------------------------------------------------------

TEST(MapJsonErrorTest, NotJsonReportsLineAndColumn) {
  EXPECT_EQ(ParseTextError("{\n  \"format\": \"warehouse-map\",\n  \"version\" 1\n}"),
            "not valid JSON: line 3, column 13 (byte 44): syntax error while parsing object "
            "separator - unexpected number literal; expected ':'");
  const std::string empty = ParseTextError("");
  EXPECT_EQ(empty.rfind("not valid JSON: line 1, column 1 (byte 1): syntax error", 0), 0u)
      << empty;
  const std::string truncated = ParseTextError("{\"format\": \"warehouse-map\", \"points\": [");
  EXPECT_NE(truncated.find("line 1, column 40"), std::string::npos) << truncated;
  EXPECT_NE(truncated.find("unexpected end of input"), std::string::npos) << truncated;
}

TEST(MapJsonErrorTest, TopLevelMustBeAnObject) {
  EXPECT_EQ(ParseTextError("[1, 2]"), "top level: expected an object, got array");
}

TEST(MapJsonErrorTest, WrongFormat) {
  json doc = SampleDoc();
  doc["format"] = "robot-fleet";
  EXPECT_EQ(ParseError(doc),
            "format: expected \"warehouse-map\", got \"robot-fleet\" (not a warehouse map file)");
  doc.erase("format");
  EXPECT_EQ(ParseError(doc), "top level: missing required field 'format'");
}

TEST(MapJsonErrorTest, UnsupportedVersion) {
  json doc = SampleDoc();
  doc["version"] = 2;
  EXPECT_EQ(ParseError(doc), "version: unsupported version 2 (this reader supports version 1)");
  doc["version"] = "1";
  EXPECT_EQ(ParseError(doc), "version: expected an integer, got string");
}

TEST(MapJsonErrorTest, MissingRequiredField) {
  json doc = SampleDoc();
  doc["points"][1].erase("x");
  EXPECT_EQ(ParseError(doc), "points[1]: missing required field 'x'");
  doc = SampleDoc();
  doc.erase("points");
  EXPECT_EQ(ParseError(doc), "top level: missing required field 'points'");
  doc = SampleDoc();
  doc["stations"][0].erase("capacity");
  EXPECT_EQ(ParseError(doc), "stations[0]: missing required field 'capacity'");
  doc = SampleDoc();
  doc.erase("floor");
  EXPECT_EQ(ParseError(doc), "top level: missing required field 'floor'");
}

TEST(MapJsonErrorTest, WrongTypes) {
  json doc = SampleDoc();
  doc["points"][3]["x"] = "5";
  EXPECT_EQ(ParseError(doc), "points[3].x: expected a number, got string");
  doc = SampleDoc();
  doc["paths"][2]["bidirectional"] = "yes";
  EXPECT_EQ(ParseError(doc), "paths[2].bidirectional: expected a boolean, got string");
  doc = SampleDoc();
  doc["stations"][0]["capacity"] = 1.5;
  EXPECT_EQ(ParseError(doc), "stations[0].capacity: expected an integer, got number");
  doc = SampleDoc();
  doc["zones"][0]["polygon"][2] = json::array({1, 2, 3});
  EXPECT_EQ(ParseError(doc),
            "zones[0].polygon[2]: expected an array [x, y] of 2 numbers, got 3 elements");
  doc = SampleDoc();
  doc["shelves"][0]["min"][1] = nullptr;
  EXPECT_EQ(ParseError(doc), "shelves[0].min[1]: expected a number, got null");
  doc = SampleDoc();
  doc["paths"] = json::object();
  EXPECT_EQ(ParseError(doc), "paths: expected an array, got object");
  doc = SampleDoc();
  doc["intersections"][0]["inner"] = "b";
  EXPECT_EQ(ParseError(doc), "intersections[0].inner: expected an array of point ids, got string");
  doc = SampleDoc();
  doc["points"][0] = 7;
  EXPECT_EQ(ParseError(doc), "points[0]: expected an object, got number");
}

TEST(MapJsonErrorTest, UnknownKind) {
  json doc = SampleDoc();
  doc["points"][2]["kind"] = "shelf";
  EXPECT_EQ(ParseError(doc),
            "points[2].kind: unknown point kind 'shelf' for point 'c' (expected lane, "
            "intersection, pick, drop, park or charge)");
}

TEST(MapJsonErrorTest, UnknownFieldIsATypo) {
  json doc = SampleDoc();
  doc["paths"][0]["lenght"] = 3;
  EXPECT_EQ(ParseError(doc), "paths[0]: unknown field 'lenght'");
  doc = SampleDoc();
  doc["robots"] = json::array();
  EXPECT_EQ(ParseError(doc), "top level: unknown field 'robots'");
}

TEST(MapJsonErrorTest, DanglingPathEnd) {
  json doc = SampleDoc();
  doc["paths"][4]["to"] = "nowhere";
  const std::string message = ParseError(doc);
  EXPECT_NE(message.find("path 4"), std::string::npos) << message;
  EXPECT_NE(message.find("unknown point 'nowhere'"), std::string::npos) << message;
}

TEST(MapJsonErrorTest, DuplicateIds) {
  json doc = SampleDoc();
  doc["points"][4]["id"] = "a";
  std::string message = ParseError(doc);
  EXPECT_NE(message.find("'a'"), std::string::npos) << message;
  EXPECT_NE(message.find("duplicate"), std::string::npos) << message;
  doc = SampleDoc();
  doc["zones"][1]["id"] = "A";
  message = ParseError(doc);
  EXPECT_NE(message.find("'A'"), std::string::npos) << message;
  EXPECT_NE(message.find("duplicate"), std::string::npos) << message;
}

TEST(MapJsonErrorTest, PointOutsideItsZone) {
  json doc = SampleDoc();
  doc["points"][4]["zone"] = "A";  // e at (12, 2) is in B
  const std::string message = ParseError(doc);
  EXPECT_NE(message.find("'e'"), std::string::npos) << message;
  EXPECT_NE(message.find("outside its zone 'A'"), std::string::npos) << message;
  doc = SampleDoc();
  doc["points"][0]["zone"] = "Q";
  EXPECT_NE(ParseError(doc).find("unknown zone 'Q'"), std::string::npos);
}

TEST(MapJsonErrorTest, NonPositiveOrTooShortLength) {
  json doc = SampleDoc();
  doc["paths"][3]["length"] = 0;
  EXPECT_EQ(ParseError(doc), "paths[3].length: path c -> e has non-positive length 0");
  doc["paths"][3]["length"] = 1.0;  // straight distance is sqrt(10)
  const std::string message = ParseError(doc);
  EXPECT_NE(message.find("c -> e"), std::string::npos) << message;
  EXPECT_NE(message.find("shorter than the straight distance"), std::string::npos) << message;
}

TEST(MapJsonErrorTest, DisconnectedDropPoint) {
  json doc = SampleDoc();
  doc["paths"].erase(4);  // e -> f: the drop point e becomes a dead end
  const std::string message = ParseError(doc);
  EXPECT_NE(message.find("drop point 'e'"), std::string::npos) << message;
  EXPECT_NE(message.find("cannot be reached"), std::string::npos) << message;
}

TEST(MapJsonErrorTest, BadStationAndIntersection) {
  json doc = SampleDoc();
  doc["stations"][0]["capacity"] = 0;
  EXPECT_EQ(ParseError(doc), "stations[0].capacity: station 'S1' needs capacity >= 1, got 0");
  doc = SampleDoc();
  doc["stations"][0]["point"] = "d";
  EXPECT_NE(ParseError(doc).find("point 'd' is a pick point"), std::string::npos);
  doc = SampleDoc();
  doc["intersections"][0]["approach"].push_back("b");
  EXPECT_NE(ParseError(doc).find("approach point 'b' lies inside intersection 'X1' (both inner and approach)"), std::string::npos);
}

TEST(MapJsonErrorTest, EmptyIdsAreRejected) {
  json doc = SampleDoc();
  doc["points"][0]["id"] = "";
  EXPECT_EQ(ParseError(doc), "points[0].id: must not be empty");
}

}  // namespace
}  // namespace dispatch::engine
