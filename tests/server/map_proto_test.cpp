// GetMap's floor message: free-space regions (issue 17 §3) go out with their polygon, area
// and the points in them.
#include <gtest/gtest.h>

#include "engine/map/map_builder.h"
#include "server/proto_convert.h"

namespace dispatch::server {
namespace {

TEST(MapToProtoTest, FreeSpacesGoOutWithTheirPolygonAreaAndPoints) {
  engine::MapBuilder b("f");
  b.SetFloor({0, 0}, {10, 4});
  b.AddRectZone("z", {0, 0}, {10, 4});
  b.AddPoint("a", {1, 1}, engine::PointKind::kPick);
  b.AddPoint("b", {8, 1}, engine::PointKind::kDrop);
  b.AddPath("a", "b", std::nullopt, 0.0, true);
  b.AddShelf("s", {4, 2}, {5, 3});
  b.AddFreeSpace("dock", {{0, 0}, {3, 0}, {3, 2}, {0, 2}});
  auto map = b.Build();
  ASSERT_TRUE(map.ok()) << map.error().message;
  warehouse::dispatch::v1::GetMapResponse out;
  MapToProto(*map, "v1", &out);
  ASSERT_EQ(out.map().free_spaces_size(), 1);
  const auto& f = out.map().free_spaces(0);
  EXPECT_EQ(f.name(), "dock");
  ASSERT_EQ(f.polygon_size(), 4);
  EXPECT_DOUBLE_EQ(f.polygon(2).x(), 3.0);
  EXPECT_DOUBLE_EQ(f.polygon(2).y(), 2.0);
  EXPECT_DOUBLE_EQ(f.area(), 6.0);
  ASSERT_EQ(f.point_ids_size(), 1);
  EXPECT_EQ(f.point_ids(0), *map->FindPoint("a"));
  EXPECT_EQ(out.map().shelves_size(), 1);
}

}  // namespace
}  // namespace dispatch::server
