// The occupancy grid of a map's free-space region: free where the polygon is and no shelf;
// the hybrid A* plans a four-wheel-steer robot inside it.
#include "engine/motion/free_space_grid.h"

#include <gtest/gtest.h>

#include "engine/map/map_builder.h"
#include "engine/motion/footprint.h"
#include "engine/motion/hybrid_astar.h"

namespace dispatch::engine {
namespace {

// An L-shaped region (a 6 x 1.5 m aisle and a 1.5 x 4 m arm at its east end) with a shelf
// poking into the aisle, and two graph points in it.
WarehouseMap LMap() {
  MapBuilder b("l");
  b.SetFloor({0, 0}, {10, 6});
  b.AddRectZone("z", {0, 0}, {10, 6});
  b.AddPoint("in", {0.5, 0.75}, PointKind::kPick);
  b.AddPoint("out", {5.25, 4.5}, PointKind::kDrop);
  b.AddPoint("far", {9, 5}, PointKind::kLane);
  b.AddPath("in", "out", std::nullopt, 0.0, true);
  b.AddPath("out", "far", std::nullopt, 0.0, true);
  b.AddShelf("s", {2.0, 1.2}, {3.0, 2.0});
  b.AddFreeSpace("L", {{0, 0}, {6, 0}, {6, 5}, {4.5, 5}, {4.5, 1.5}, {0, 1.5}});
  auto map = b.Build();
  if (!map.ok()) ADD_FAILURE() << map.error().message;
  return std::move(map).value();
}

TEST(FreeSpaceGridTest, FreeInsideThePolygonOutsideShelves) {
  const WarehouseMap map = LMap();
  ASSERT_EQ(map.free_spaces().size(), 1u);
  EXPECT_EQ(map.free_spaces()[0].points, (std::vector<PointId>{*map.FindPoint("in"), *map.FindPoint("out")}));
  auto grid = FreeSpaceGrid(map, 0, 0.1);
  ASSERT_TRUE(grid.ok()) << grid.error().message;
  EXPECT_EQ(grid->width(), 60);
  EXPECT_EQ(grid->height(), 50);
  EXPECT_FALSE(grid->OccupiedAt(0.55, 0.75));  // the aisle
  EXPECT_FALSE(grid->OccupiedAt(5.25, 4.5));   // the arm
  EXPECT_TRUE(grid->OccupiedAt(2.0, 3.0));     // the L's missing corner
  EXPECT_TRUE(grid->OccupiedAt(2.5, 1.25));    // the shelf's part inside
  EXPECT_FALSE(grid->OccupiedAt(2.5, 1.15));   // just below it
  EXPECT_TRUE(grid->OccupiedAt(6.5, 1.0));     // beyond the box
  EXPECT_TRUE(grid->has_clearance());

  EXPECT_EQ(FreeSpaceGrid(map, 1, 0.1).error().code, ErrorCode::kNotFound);
  EXPECT_EQ(FreeSpaceGrid(map, 0, 0.0).error().code, ErrorCode::kInvalidArgument);
  EXPECT_EQ(FreeSpaceGrid(map, 0, 1e-5).error().code, ErrorCode::kInvalidArgument);  // 10^10 cells
}

TEST(FreeSpaceGridTest, AFourWheelSteerRobotIsPlannedThroughTheRegion) {
  const WarehouseMap map = LMap();
  auto grid = FreeSpaceGrid(map, 0, 0.1);
  ASSERT_TRUE(grid.ok()) << grid.error().message;
  FootprintChecker checker(*grid, Footprint{0.8, 0.5, 0.0});
  // From the aisle's west end, heading east, past the shelf (which leaves 1.2 m of the aisle)
  // and round the corner to the arm's top, heading north; never outside the region.
  const MotionPose start{0.6, 0.6, 0.0}, goal{5.25, 4.4, M_PI / 2};
  auto path = PlanHybridAStar(checker, start, goal);
  ASSERT_TRUE(path.ok()) << path.error().message;
  for (const MotionPose& pose : path->poses) {
    EXPECT_FALSE(checker.Collides(pose)) << pose.x << "," << pose.y;
    EXPECT_TRUE(map.free_spaces()[0].Contains({pose.x, pose.y}));
  }
  EXPECT_NEAR(path->poses.back().x, goal.x, 0.11);
  EXPECT_NEAR(path->poses.back().y, goal.y, 0.11);
}

}  // namespace
}  // namespace dispatch::engine
