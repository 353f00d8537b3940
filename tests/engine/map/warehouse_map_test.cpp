#include "engine/map/warehouse_map.h"

#include <gtest/gtest.h>

#include "engine/map/map_builder.h"

namespace dispatch::engine {
namespace {

TEST(ZoneTest, ContainsInsideBoundaryAndNotOutside) {
  Zone z{"Z", {{0, 0}, {4, 0}, {4, 2}, {0, 2}}, 8.0};
  EXPECT_TRUE(z.Contains({1, 1}));
  EXPECT_TRUE(z.Contains({4, 1}));  // on an edge
  EXPECT_TRUE(z.Contains({0, 0}));  // a vertex
  EXPECT_FALSE(z.Contains({4.01, 1}));
  EXPECT_FALSE(z.Contains({-1, -1}));
  Zone triangle{"T", {{0, 0}, {4, 0}, {0, 4}}, 8.0};
  EXPECT_TRUE(triangle.Contains({1, 1}));
  EXPECT_FALSE(triangle.Contains({3, 3}));
}

TEST(PointKindTest, NamesRoundTrip) {
  for (auto kind : {PointKind::kLane, PointKind::kIntersection, PointKind::kPick,
                    PointKind::kDrop, PointKind::kPark, PointKind::kCharge}) {
    EXPECT_EQ(ParsePointKind(PointKindName(kind)), kind);
  }
  EXPECT_FALSE(ParsePointKind("shelf").has_value());
}

class ArcPositionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    MapBuilder b("two");
    b.AddRectZone("Z", {-10, -10}, {10, 10});
    b.AddPoint("a", {0, 0}, PointKind::kPick);
    b.AddPoint("b", {4, 0}, PointKind::kLane);
    b.AddPoint("c", {4, 3}, PointKind::kDrop);
    b.AddPath("a", "b", std::nullopt, 0, true);
    b.AddPath("b", "c", std::nullopt, 0, true);
    auto built = b.Build();
    ASSERT_TRUE(built.ok()) << built.error().message;
    map_ = std::move(built).value();
  }
  WarehouseMap map_;
};

TEST_F(ArcPositionTest, ConvertsBothWays) {
  const ArcId ab = *map_.FindArc(*map_.FindPoint("a"), *map_.FindPoint("b"));
  EXPECT_TRUE(map_.PositionOf({ab, 1.5}).isApprox(Eigen::Vector2d(1.5, 0)));
  EXPECT_TRUE(map_.PositionOf({ab, 99}).isApprox(Eigen::Vector2d(4, 0)));  // clamped
  const ArcId bc = *map_.FindArc(*map_.FindPoint("b"), *map_.FindPoint("c"));
  double dist = -1;
  auto pos = map_.NearestArcPosition({4.5, 2}, &dist);
  ASSERT_TRUE(pos.ok());
  // Either direction of the b-c lane is at the same place; the position must map back.
  EXPECT_TRUE(pos->arc == bc || pos->arc == map_.arc(bc).reverse_arc);
  EXPECT_NEAR(dist, 0.5, 1e-12);
  EXPECT_TRUE(map_.PositionOf(*pos).isApprox(Eigen::Vector2d(4, 2)));
  // Round trip: every (arc, offset) projects back onto the same place.
  for (ArcId a = 0; a < static_cast<ArcId>(map_.arcs().size()); ++a) {
    for (double f : {0.1, 0.5, 0.9}) {
      const Eigen::Vector2d xy = map_.PositionOf({a, f * map_.arc(a).length});
      auto back = map_.NearestArcPosition(xy, &dist);
      ASSERT_TRUE(back.ok());
      EXPECT_NEAR(dist, 0.0, 1e-12);
      EXPECT_TRUE(map_.PositionOf(*back).isApprox(xy));
    }
  }
}

TEST_F(ArcPositionTest, NearestPointFiltersByKind) {
  double dist = 0;
  EXPECT_EQ(map_.NearestPoint({3.9, 0.2}), *map_.FindPoint("b"));
  EXPECT_EQ(map_.NearestPoint({3.9, 0.2}, PointKind::kDrop, &dist), *map_.FindPoint("c"));
  EXPECT_NEAR(dist, std::hypot(0.1, 2.8), 1e-12);
  EXPECT_EQ(map_.NearestPoint({0, 0}, PointKind::kPark), kNoPoint);
}

}  // namespace
}  // namespace dispatch::engine
