#include "engine/io/map_source.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "engine/io/map_json.h"
#include "engine/map/chu2024_floor.h"

namespace dispatch::engine {
namespace {

std::string TempFile(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("map_source_test_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(path) << text;
  return path.string();
}

TEST(MapSourceTest, BuiltInChu2024) {
  auto map = LoadMapSource("chu2024");
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(map->name(), "chu2024");
}

TEST(MapSourceTest, BuiltInWang2019) {
  auto map = LoadMapSource("wang2019");
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(map->name(), "wang2019");
  EXPECT_EQ(map->point_count(), static_cast<std::size_t>(40 * 30 - 42 * 8));
}

TEST(MapSourceTest, Chu2024SurvivesAJsonRoundTrip) {
  auto floor = BuildChu2024Floor();
  ASSERT_TRUE(floor.ok());
  const std::string json = WriteMapJson(*floor);
  const std::string path = TempFile("chu2024.json", json);
  auto back = LoadMapSource(path);
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(WriteMapJson(*back), json);
  EXPECT_EQ(back->point_count(), floor->point_count());
  EXPECT_EQ(back->arcs().size(), floor->arcs().size());
  EXPECT_EQ(back->intersections().size(), floor->intersections().size());
  std::filesystem::remove(path);
}

TEST(MapSourceTest, MovingAiFile) {
  const std::string path =
      TempFile("tiny.map", "type octile\nheight 2\nwidth 3\nmap\n.S.\nE@.\n");
  auto map = LoadMapSource(path);
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(map->point_count(), 5u);
  std::filesystem::remove(path);
}

TEST(MapSourceTest, UnknownFormsAndMissingFilesAreClearErrors) {
  auto bad = LoadMapSource("warehouse.txt");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("expected 'chu2024', 'wang2019', a .json map file or a MovingAI .map file"),
            std::string::npos);
  auto missing = LoadMapSource("/nonexistent/floor.json");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("/nonexistent/floor.json"), std::string::npos);
}

}  // namespace
}  // namespace dispatch::engine
