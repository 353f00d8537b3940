// Occupancy grid and footprint collision checks (engine/motion/occupancy_grid.h, footprint.h).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "engine/map/grid_floor.h"
#include "engine/motion/footprint.h"
#include "engine/motion/occupancy_grid.h"

namespace dispatch::engine {
namespace {

TEST(OccupancyGridTest, FromMapMarksExactlyTheShelves) {
  GridFloorOptions options;
  options.shelf_rows = 2;
  options.shelf_cols = 2;
  Result<WarehouseMap> map = BuildGridFloor(options);
  ASSERT_TRUE(map.ok()) << map.error().message;
  Result<OccupancyGrid> grid = OccupancyGrid::FromMap(*map, 0.25);
  ASSERT_TRUE(grid.ok()) << grid.error().message;
  ASSERT_FALSE(map->shelves().empty());
  int occupied = 0;
  for (int iy = 0; iy < grid->height(); ++iy) {
    for (int ix = 0; ix < grid->width(); ++ix) {
      const double x = grid->origin().x() + (ix + 0.5) * 0.25;
      const double y = grid->origin().y() + (iy + 0.5) * 0.25;
      bool in_shelf = false;
      for (const Shelf& s : map->shelves()) {
        in_shelf = in_shelf || (x > s.min.x() && x < s.max.x() && y > s.min.y() && y < s.max.y());
      }
      EXPECT_EQ(grid->Occupied(ix, iy), in_shelf) << ix << "," << iy;
      occupied += grid->Occupied(ix, iy) ? 1 : 0;
    }
  }
  EXPECT_GT(occupied, 0);
  EXPECT_TRUE(grid->Occupied(-1, 0));
  EXPECT_TRUE(grid->Occupied(0, grid->height()));
  EXPECT_FALSE(OccupancyGrid::FromMap(*map, 0.0).ok());
}

TEST(OccupancyGridTest, FromMovingAiSubdividesTilesWithYUp) {
  const Result<OccupancyGrid> grid =
      OccupancyGrid::FromMovingAi("type octile\nheight 2\nwidth 3\nmap\n@..\n.T.\n", 1.0, 10);
  ASSERT_TRUE(grid.ok()) << grid.error().message;
  EXPECT_EQ(grid->width(), 30);
  EXPECT_EQ(grid->height(), 20);
  EXPECT_DOUBLE_EQ(grid->resolution(), 0.1);
  EXPECT_TRUE(grid->OccupiedAt(0.5, 1.5));   // '@' top-left
  EXPECT_TRUE(grid->OccupiedAt(1.95, 0.05)); // 'T' bottom-middle
  EXPECT_FALSE(grid->OccupiedAt(0.5, 0.5));
  EXPECT_FALSE(grid->OccupiedAt(2.5, 1.5));
  EXPECT_TRUE(grid->has_clearance());
  EXPECT_FALSE(OccupancyGrid::FromMovingAi("type octile\nheight 2\nwidth 3\nmap\n@..\n", 1.0).ok());
  EXPECT_FALSE(OccupancyGrid::FromMovingAi("height 1\nwidth 3\nmap\n@.\n", 1.0).ok());
}

TEST(OccupancyGridTest, ClearanceIsDistanceToNearestObstacleOrEdge) {
  OccupancyGrid grid(21, 21, 0.1);
  grid.Set(10, 10, true);
  grid.ComputeClearance();
  EXPECT_DOUBLE_EQ(grid.Clearance(10, 10), 0.0);
  EXPECT_NEAR(grid.Clearance(13, 14), 0.5, 1e-12);  // 3-4-5 from the obstacle
  EXPECT_NEAR(grid.Clearance(0, 10), 0.05, 1e-12);  // half a cell to the edge
}

class FootprintTest : public ::testing::Test {
 protected:
  FootprintTest() : grid_(40, 40, 0.1) {
    grid_.Set(20, 20, true);  // the cell [2.0, 2.1] x [2.0, 2.1]
    grid_.ComputeClearance();
  }
  OccupancyGrid grid_;
};

TEST_F(FootprintTest, RectangleAlongAndAcrossTheHeading) {
  const FootprintChecker checker(grid_, {0.8, 0.5, 0.0});
  EXPECT_FALSE(checker.Collides({1.55, 2.05, 0.0}));               // front at 1.95
  EXPECT_TRUE(checker.Collides({1.7, 2.05, 0.0}));                 // front at 2.1
  EXPECT_FALSE(checker.Collides({1.7, 2.05, std::numbers::pi / 2}));  // side at 1.95
  EXPECT_TRUE(checker.Collides({1.85, 2.05, std::numbers::pi / 2}));  // side at 2.1
  EXPECT_TRUE(checker.Collides({2.05, 2.05, 0.3}));                // centre on the obstacle
  EXPECT_TRUE(checker.Collides({0.3, 1.0, 0.0}));                  // rear off the grid
  EXPECT_FALSE(checker.Collides({0.45, 1.0, 0.0}));
  // A margin grows the rectangle.
  const FootprintChecker padded(grid_, {0.8, 0.5, 0.1});
  EXPECT_TRUE(padded.Collides({1.55, 2.05, 0.0}));
}

// Model check against dense sampling (1 cm): a sample of the rectangle in an occupied cell
// is a real overlap, so it must be reported; a reported overlap must show up in the samples
// of the rectangle grown by 1 cm (slivers thinner than the sampling). The fast path
// (clearance) must agree with the row scan everywhere.
TEST(FootprintModelTest, AgreesWithDenseSamplingOnRandomGrids) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> pos(0.0, 3.0);
  std::uniform_real_distribution<double> ang(-std::numbers::pi, std::numbers::pi);
  for (int round = 0; round < 5; ++round) {
    OccupancyGrid grid(30, 30, 0.1);
    for (int k = 0; k < 25; ++k) grid.Set(static_cast<int>(rng() % 30), static_cast<int>(rng() % 30), true);
    OccupancyGrid no_clearance = grid;
    grid.ComputeClearance();
    const Footprint fp{0.6, 0.4, 0.0};
    const FootprintChecker checker(grid, fp);
    const FootprintChecker slow(no_clearance, fp);
    auto dense = [&](const MotionPose& p, double grow) {
      const double hl = fp.length / 2 + grow;
      const double hw = fp.width / 2 + grow;
      for (double a = -hl; a <= hl + 1e-9; a += 0.01) {
        for (double b = -hw; b <= hw + 1e-9; b += 0.01) {
          if (grid.OccupiedAt(p.x + std::cos(p.theta) * a - std::sin(p.theta) * b,
                              p.y + std::sin(p.theta) * a + std::cos(p.theta) * b)) {
            return true;
          }
        }
      }
      return false;
    };
    int collisions = 0;
    for (int k = 0; k < 300; ++k) {
      const MotionPose p{pos(rng), pos(rng), ang(rng)};
      const bool hit = checker.Collides(p);
      EXPECT_EQ(hit, slow.Collides(p));
      if (hit) {
        EXPECT_TRUE(dense(p, 0.01)) << p.x << " " << p.y << " " << p.theta;
      }
      if (dense(p, 0.0)) {
        EXPECT_TRUE(hit) << p.x << " " << p.y << " " << p.theta;
      }
      collisions += hit ? 1 : 0;
    }
    EXPECT_GT(collisions, 0);
    EXPECT_LT(collisions, 300);
  }
}

}  // namespace
}  // namespace dispatch::engine
