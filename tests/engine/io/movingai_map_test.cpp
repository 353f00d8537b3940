#include "engine/io/movingai_map.h"

#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <string>

namespace dispatch::engine {
namespace {

// Row 0: S . . @ .      ids 0..4
// Row 1: . @ E @ G      ids 5..9
// Row 2: . . T . W      ids 10..14
// Largest component: 0 1 2 5 7 10 11 (7 cells). Dropped: 4 and 9 (a pair), 13 (alone).
constexpr const char* kTiny =
    "type octile\n"
    "height 3\n"
    "width 5\n"
    "map\n"
    "S..@.\n"
    ".@E@G\n"
    "..T.W\n";

std::string ErrorOf(const std::string& text) {
  Result<WarehouseMap> map = ParseMovingAiMap(text, "bad");
  if (map) return "(parsed without error)";
  EXPECT_EQ(map.error().code, ErrorCode::kInvalidArgument);
  return map.error().message;
}

std::string Tiny(const std::string& rows, const std::string& header = "type octile\nheight 3\nwidth 5\nmap\n") {
  return header + rows;
}

TEST(MovingAiMapTest, CellsBecomePointsNamedByLorrCellId) {
  MovingAiImportReport report;
  Result<WarehouseMap> map = ParseMovingAiMap(kTiny, "tiny", {}, &report);
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(map->name(), "tiny");
  EXPECT_EQ(report.height, 3);
  EXPECT_EQ(report.width, 5);
  EXPECT_EQ(report.free_cells, 10);
  EXPECT_EQ(report.dropped_cells, 3);
  EXPECT_EQ(report.points, 7);
  EXPECT_EQ(report.lanes, 6);
  EXPECT_EQ(report.zones, 1);
  EXPECT_EQ(map->point_count(), 7u);
  for (const char* dropped : {"c3", "c4", "c6", "c8", "c9", "c12", "c13", "c14"}) {
    EXPECT_FALSE(map->FindPoint(dropped).has_value()) << dropped;
  }
  // x = col, y = H-1-row.
  const Point& s = map->point(*map->FindPoint("c0"));
  EXPECT_EQ(s.position, Eigen::Vector2d(0, 2));
  EXPECT_EQ(s.kind, PointKind::kPick);
  const Point& e = map->point(*map->FindPoint("c7"));
  EXPECT_EQ(e.position, Eigen::Vector2d(2, 1));
  EXPECT_EQ(e.kind, PointKind::kDrop);
  const Point& lane = map->point(*map->FindPoint("c11"));
  EXPECT_EQ(lane.position, Eigen::Vector2d(1, 0));
  EXPECT_EQ(lane.kind, PointKind::kLane);
  EXPECT_EQ(map->floor_min(), Eigen::Vector2d(-0.5, -0.5));
  EXPECT_EQ(map->floor_max(), Eigen::Vector2d(4.5, 2.5));
  EXPECT_TRUE(map->intersections().empty());
}

TEST(MovingAiMapTest, FourConnectedBidirectionalSingleLanes) {
  Result<WarehouseMap> map = ParseMovingAiMap(kTiny, "tiny");
  ASSERT_TRUE(map.ok()) << map.error().message;
  ASSERT_EQ(map->paths().size(), 6u);
  EXPECT_EQ(map->arcs().size(), 12u);
  for (const Path& p : map->paths()) {
    EXPECT_TRUE(p.bidirectional);
    EXPECT_DOUBLE_EQ(p.length, 1.0);
    EXPECT_LT(p.from, p.to);  // written from the lower cell id
  }
  auto id = [&](const char* name) { return *map->FindPoint(name); };
  const std::pair<const char*, const char*> adjacent[] = {
      {"c0", "c1"}, {"c1", "c2"}, {"c0", "c5"}, {"c2", "c7"}, {"c5", "c10"}, {"c10", "c11"}};
  for (const auto& [a, b] : adjacent) {
    auto fwd = map->FindArc(id(a), id(b));
    auto back = map->FindArc(id(b), id(a));
    ASSERT_TRUE(fwd && back) << a << " - " << b;
    EXPECT_TRUE(map->arc(*fwd).single_lane());
    EXPECT_EQ(map->arc(*fwd).reverse_arc, *back);
  }
  EXPECT_FALSE(map->FindArc(id("c5"), id("c1")));   // diagonal
  EXPECT_FALSE(map->FindArc(id("c1"), id("c11")));  // not adjacent
  EXPECT_FALSE(map->FindArc(id("c7"), id("c11")));  // diagonal
}

TEST(MovingAiMapTest, AllFreeAndBlockedCharacters) {
  Result<WarehouseMap> map =
      ParseMovingAiMap("type octile\nheight 2\nwidth 4\nmap\n.GSE\n@TOW\n", "chars");
  ASSERT_TRUE(map.ok()) << map.error().message;
  ASSERT_EQ(map->point_count(), 4u);
  EXPECT_EQ(map->point(*map->FindPoint("c0")).kind, PointKind::kLane);
  EXPECT_EQ(map->point(*map->FindPoint("c1")).kind, PointKind::kLane);
  EXPECT_EQ(map->point(*map->FindPoint("c2")).kind, PointKind::kPick);
  EXPECT_EQ(map->point(*map->FindPoint("c3")).kind, PointKind::kDrop);
  EXPECT_EQ(map->point(*map->FindPoint("c0")).position, Eigen::Vector2d(0, 1));
}

TEST(MovingAiMapTest, ZonesAreTilesHoldingKeptCells) {
  MovingAiImportReport report;
  Result<WarehouseMap> map = ParseMovingAiMap(kTiny, "tiny", {.tile_cells = 2}, &report);
  ASSERT_TRUE(map.ok()) << map.error().message;
  // Tiles (rows 0-1 | row 2) x (cols 0-1 | 2-3 | 4): t0_2 and t1_1 hold only dropped cells.
  ASSERT_EQ(map->zones().size(), 3u);
  EXPECT_EQ(report.zones, 3);
  EXPECT_EQ(map->zones()[0].name, "t0_0");
  EXPECT_EQ(map->zones()[1].name, "t0_1");
  EXPECT_EQ(map->zones()[2].name, "t1_0");
  EXPECT_DOUBLE_EQ(map->zones()[0].area, 4.0);
  EXPECT_DOUBLE_EQ(map->zones()[2].area, 2.0);  // clipped by the floor
  EXPECT_EQ(map->point(*map->FindPoint("c0")).zone, 0);
  EXPECT_EQ(map->point(*map->FindPoint("c7")).zone, 1);
  EXPECT_EQ(map->point(*map->FindPoint("c11")).zone, 2);
  EXPECT_FALSE(ParseMovingAiMap(kTiny, "tiny", {.tile_cells = 0}).ok());
}

TEST(MovingAiMapTest, WindowsLineEndingsAndTrailingBlankLines) {
  Result<WarehouseMap> map = ParseMovingAiMap(
      "type octile\r\nheight 1\r\nwidth 3\r\nmap\r\n.S.\r\n\r\n", "crlf");
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(map->point_count(), 3u);
}

TEST(MovingAiMapErrorTest, RowOfWrongLength) {
  EXPECT_EQ(ErrorOf(Tiny("S..@.\n.@E@\n..T.W\n")), "line 6: expected 5 characters, got 4");
  EXPECT_EQ(ErrorOf(Tiny("S..@.\n.@E@G.\n..T.W\n")), "line 6: expected 5 characters, got 6");
}

TEST(MovingAiMapErrorTest, UnknownCharacterNamesLineAndColumn) {
  EXPECT_EQ(ErrorOf(Tiny("S..@.\n.@E@G\n..x.W\n")),
            "line 7, column 3: unknown character 'x' (free: . G S E; blocked: @ T O W)");
  EXPECT_EQ(ErrorOf(Tiny("S..@.\n.@E@G\n..\t.W\n")),
            "line 7, column 3: unknown character 0x09 (free: . G S E; blocked: @ T O W)");
}

TEST(MovingAiMapErrorTest, BadHeader) {
  EXPECT_EQ(ErrorOf("type octile\nheigth 3\nwidth 5\nmap\n"),
            "line 2: bad header: expected 'type', 'height', 'width' or 'map', got 'heigth 3'");
  EXPECT_EQ(ErrorOf("type octile\nheight three\nwidth 5\nmap\n"),
            "line 2: bad header: height must be a positive integer, got 'three'");
  EXPECT_EQ(ErrorOf("type octile\nheight 3\nwidth -5\nmap\n"),
            "line 3: bad header: width must be a positive integer, got '-5'");
  EXPECT_EQ(ErrorOf("type hex\nheight 3\nwidth 5\nmap\n"),
            "line 1: bad header: unsupported map type 'hex' (expected 'octile')");
  EXPECT_EQ(ErrorOf("type octile\nheight 3\nmap\n"), "line 3: bad header: 'map' before the 'width' line");
  EXPECT_EQ(ErrorOf("type octile\nheight 3\nwidth 5\n"),
            "line 4: bad header: missing the 'map' line (expected 'type octile', 'height H', "
            "'width W', 'map')");
  EXPECT_EQ(ErrorOf(""),
            "line 1: bad header: missing the 'map' line (expected 'type octile', 'height H', "
            "'width W', 'map')");
}

TEST(MovingAiMapErrorTest, MissingRows) {
  EXPECT_EQ(ErrorOf(Tiny("S..@.\n.@E@G\n")),
            "line 7: missing rows: the header declares height 3, the file has 2 rows");
}

TEST(MovingAiMapErrorTest, ExtraRows) {
  EXPECT_EQ(ErrorOf(Tiny("S..@.\n.@E@G\n..T.W\n.....\n")),
            "line 8: extra row: the header declares height 3");
}

TEST(MovingAiMapErrorTest, NoFreeCells) {
  EXPECT_EQ(ErrorOf("type octile\nheight 1\nwidth 2\nmap\n@T\n"),
            "MovingAI map 'bad' has no free cells");
}

TEST(MovingAiMapErrorTest, FileErrorsNameThePath) {
  Result<WarehouseMap> map = LoadMovingAiMapFile("/nonexistent/x.map");
  ASSERT_FALSE(map.ok());
  EXPECT_EQ(map.error().code, ErrorCode::kIoError);
  EXPECT_NE(map.error().message.find("/nonexistent/x.map"), std::string::npos);
}

// --- The public LoRR 2024 floors -----------------------------------------------------------

struct CharCounts {
  int free = 0, pick = 0, drop = 0, height = 0, width = 0;
};

// Counts the characters of a .map file independently of the importer.
CharCounts CountChars(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  std::string line;
  CharCounts counts;
  int header = 0;
  while (header < 4 && std::getline(in, line)) {
    ++header;
    if (line.rfind("height ", 0) == 0) counts.height = std::stoi(line.substr(7));
    if (line.rfind("width ", 0) == 0) counts.width = std::stoi(line.substr(6));
  }
  while (std::getline(in, line)) {
    for (char c : line) {
      counts.free += (c == '.' || c == 'G' || c == 'S' || c == 'E') ? 1 : 0;
      counts.pick += c == 'S' ? 1 : 0;
      counts.drop += c == 'E' ? 1 : 0;
    }
  }
  return counts;
}

class LorrMapTest : public ::testing::TestWithParam<const char*> {};

TEST_P(LorrMapTest, LoadsWithExactCellCounts) {
  const std::string path =
      std::string(DISPATCH_SHARED_DIR "/benchmarks/lorr2024/example_problems/") + GetParam();
  const CharCounts expected = CountChars(path);
  MovingAiImportReport report;
  const auto start = std::chrono::steady_clock::now();
  Result<WarehouseMap> map = LoadMovingAiMapFile(path, {}, &report);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(map.ok()) << map.error().message;
  RecordProperty("load_seconds", std::to_string(seconds));
  std::printf("%s: %d points, %d lanes, %d zones, %d dropped, %.3f s\n", GetParam(),
              report.points, report.lanes, report.zones, report.dropped_cells, seconds);
  EXPECT_EQ(report.height, expected.height);
  EXPECT_EQ(report.width, expected.width);
  EXPECT_EQ(report.free_cells, expected.free);
  EXPECT_EQ(static_cast<int>(map->point_count()) + report.dropped_cells, expected.free);
  EXPECT_EQ(report.points, static_cast<int>(map->point_count()));
  EXPECT_EQ(report.lanes, static_cast<int>(map->paths().size()));
  EXPECT_EQ(map->arcs().size(), 2 * map->paths().size());
  int picks = 0, drops = 0;
  for (const Point& p : map->points()) {
    picks += p.kind == PointKind::kPick ? 1 : 0;
    drops += p.kind == PointKind::kDrop ? 1 : 0;
    // Name <-> position: c<row*W+col>, x = col, y = H-1-row.
    const int id = std::stoi(p.name.substr(1));
    EXPECT_EQ(p.position.x(), id % expected.width);
    EXPECT_EQ(p.position.y(), expected.height - 1 - id / expected.width);
  }
  EXPECT_LE(picks, expected.pick);
  EXPECT_LE(drops, expected.drop);
  const std::string file = GetParam();
  const std::size_t slash = file.rfind('/');
  EXPECT_EQ(map->name(), file.substr(slash + 1, file.rfind(".map") - slash - 1));
  EXPECT_LT(seconds, 3.0) << "import is too slow";  // ~0.3 s expected; generous under load
}

INSTANTIATE_TEST_SUITE_P(Lorr2024, LorrMapTest,
                         ::testing::Values("random.domain/maps/random-32-32-20.map",
                                           "warehouse.domain/maps/warehouse_large.map",
                                           "warehouse.domain/maps/sortation_large.map"));

TEST(LorrMapCountTest, WarehouseLargeHas38586FreeCells) {
  const CharCounts counts = CountChars(
      DISPATCH_SHARED_DIR "/benchmarks/lorr2024/example_problems/warehouse.domain/maps/"
                          "warehouse_large.map");
  EXPECT_EQ(counts.free, 38586);
  EXPECT_EQ(counts.height, 140);
  EXPECT_EQ(counts.width, 500);
}

}  // namespace
}  // namespace dispatch::engine
