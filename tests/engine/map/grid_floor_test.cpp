// The parameterised grid floor (benchmarks, large-fleet simulations).
#include "engine/map/grid_floor.h"

#include <gtest/gtest.h>

namespace dispatch::engine {
namespace {

TEST(GridFloorTest, SizesKindsAndLanes) {
  GridFloorOptions o;
  o.shelf_rows = 3;
  o.shelf_cols = 4;
  auto map = BuildGridFloor(o);
  ASSERT_TRUE(map.ok()) << map.error().message;
  const int w = 2 * 2 + 4 * 4 + 3 * 2, h = 2 * 2 + 3 * 2 + 2 * 2;  // 26 x 14 cells
  EXPECT_EQ(map->point_count(), static_cast<std::size_t>(w * h - 12 * 8));
  EXPECT_EQ(map->shelves().size(), 12u);
  std::size_t picks = 0, drops = 0;
  for (const Point& p : map->points()) {
    picks += p.kind == PointKind::kPick;
    drops += p.kind == PointKind::kDrop;
    for (const Shelf& s : map->shelves()) {  // no point inside a shelf
      EXPECT_FALSE(p.position.x() > s.min.x() && p.position.x() < s.max.x() &&
                   p.position.y() > s.min.y() && p.position.y() < s.max.y())
          << p.name;
    }
  }
  EXPECT_EQ(picks, 24u);                         // north and south of every shelf
  EXPECT_EQ(drops, 2u * ((h + 3) / 4));          // every 4th cell, left and right
  for (const Path& p : map->paths()) {
    EXPECT_TRUE(p.bidirectional);
    EXPECT_DOUBLE_EQ(p.length, 1.0);
  }
  EXPECT_TRUE(map->intersections().empty());
}

// Wang2019 §4's 40 x 30 grid: 3 free columns left and right, 2 free rows above and below.
TEST(GridFloorTest, Wang2019FloorIsFortyByThirty) {
  auto map = BuildWang2019Floor();
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(map->name(), "wang2019");
  EXPECT_EQ(map->shelves().size(), 42u);
  EXPECT_EQ(map->point_count(), static_cast<std::size_t>(40 * 30 - 42 * 8));
  EXPECT_DOUBLE_EQ(map->floor_max().x(), 39.5);
  EXPECT_DOUBLE_EQ(map->floor_max().y(), 29.5);
  EXPECT_DOUBLE_EQ(map->shelves().front().min.y(), 1.5);  // rows 0 and 1 free
  EXPECT_DOUBLE_EQ(map->shelves().front().min.x(), 2.5);  // columns 0-2 free
}

TEST(GridFloorTest, RejectsBadSizes) {
  GridFloorOptions o;
  o.aisle = 0;
  EXPECT_FALSE(BuildGridFloor(o).ok());
  o.aisle = 2;
  o.border_y = -1;
  EXPECT_FALSE(BuildGridFloor(o).ok());
}

}  // namespace
}  // namespace dispatch::engine
