#include "engine/map/map_builder.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace dispatch::engine {
namespace {

using ::testing::HasSubstr;

// A square loop a -> b -> c -> d -> a with a pick and a drop, all in one zone.
MapBuilder LoopBuilder() {
  MapBuilder b("loop");
  b.AddRectZone("Z", {0, 0}, {10, 10});
  b.AddPoint("a", {1, 1}, PointKind::kPick);
  b.AddPoint("b", {5, 1}, PointKind::kLane);
  b.AddPoint("c", {5, 5}, PointKind::kDrop);
  b.AddPoint("d", {1, 5}, PointKind::kLane);
  b.AddPath("a", "b");
  b.AddPath("b", "c");
  b.AddPath("c", "d");
  b.AddPath("d", "a");
  return b;
}

std::string BuildError(const MapBuilder& b) {
  auto result = b.Build();
  EXPECT_FALSE(result.ok());
  return result.ok() ? "" : result.error().message;
}

TEST(MapBuilderTest, BuildsArcsAdjacencyAndZones) {
  auto map = LoopBuilder().Build();
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(map->point_count(), 4u);
  EXPECT_EQ(map->arcs().size(), 4u);
  EXPECT_DOUBLE_EQ(map->arc(0).length, 4.0);
  EXPECT_DOUBLE_EQ(map->zones()[0].area, 100.0);
  const PointId a = *map->FindPoint("a");
  const PointId b = *map->FindPoint("b");
  ASSERT_EQ(map->out_arcs(a).size(), 1u);
  EXPECT_EQ(map->arc(map->out_arcs(a)[0]).to, b);
  EXPECT_TRUE(map->FindArc(a, b).has_value());
  EXPECT_FALSE(map->FindArc(b, a).has_value());
  EXPECT_EQ(map->floor_min(), Eigen::Vector2d(0, 0));
  EXPECT_EQ(map->floor_max(), Eigen::Vector2d(10, 10));
}

TEST(MapBuilderTest, BidirectionalLaneYieldsTwoLinkedArcs) {
  MapBuilder b("lane");
  b.AddRectZone("Z", {0, 0}, {10, 10});
  b.AddPoint("a", {1, 1}, PointKind::kPick);
  b.AddPoint("b", {4, 1}, PointKind::kDrop);
  b.AddPath("a", "b", 3.5, 0.0, true);
  auto map = b.Build();
  ASSERT_TRUE(map.ok()) << map.error().message;
  ASSERT_EQ(map->arcs().size(), 2u);
  EXPECT_EQ(map->arc(0).reverse_arc, 1);
  EXPECT_EQ(map->arc(1).reverse_arc, 0);
  EXPECT_DOUBLE_EQ(map->arc(1).length, 3.5);
  EXPECT_TRUE(map->arc(0).single_lane());
}

TEST(MapBuilderTest, RejectsDanglingPathEnd) {
  MapBuilder b = LoopBuilder();
  b.AddPath("a", "nowhere");
  EXPECT_THAT(BuildError(b), HasSubstr("unknown point 'nowhere'"));
}

TEST(MapBuilderTest, RejectsDuplicatePointId) {
  MapBuilder b = LoopBuilder();
  b.AddPoint("a", {2, 2}, PointKind::kLane);
  EXPECT_THAT(BuildError(b), HasSubstr("duplicate point id"));
}

TEST(MapBuilderTest, RejectsNonPositiveAndTooShortLengths) {
  MapBuilder zero = LoopBuilder();
  zero.AddPath("a", "c", 0.0);
  EXPECT_THAT(BuildError(zero), HasSubstr("length must be a positive number"));
  MapBuilder negative = LoopBuilder();
  negative.AddPath("a", "c", -1.0);
  EXPECT_THAT(BuildError(negative), HasSubstr("length must be a positive number"));
  MapBuilder shorter = LoopBuilder();
  shorter.AddPath("a", "c", 1.0);
  EXPECT_THAT(BuildError(shorter), HasSubstr("shorter than the straight distance"));
}

TEST(MapBuilderTest, RejectsPointOutsideZones) {
  MapBuilder b = LoopBuilder();
  b.AddPoint("far", {20, 20}, PointKind::kLane);
  EXPECT_THAT(BuildError(b), HasSubstr("'far') at (20, 20) lies in no zone"));
  MapBuilder named = LoopBuilder();
  named.AddRectZone("Small", {0, 0}, {2, 2});
  named.AddPoint("e", {5, 6}, PointKind::kLane, "Small");
  EXPECT_THAT(BuildError(named), HasSubstr("lies outside its zone 'Small'"));
}

TEST(MapBuilderTest, RejectsDisconnectedDropPoint) {
  MapBuilder b = LoopBuilder();
  b.AddPoint("island", {8, 8}, PointKind::kDrop);
  EXPECT_THAT(BuildError(b), HasSubstr("drop point 'island' cannot be reached"));
  // Reachable one way only is still disconnected.
  MapBuilder one_way = LoopBuilder();
  one_way.AddPoint("sink", {8, 8}, PointKind::kDrop);
  one_way.AddPath("c", "sink");
  EXPECT_THAT(BuildError(one_way), HasSubstr("cannot be reached from drop point 'sink'"));
}

TEST(MapBuilderTest, RejectsBadIntersectionsStationsShelvesZones) {
  MapBuilder inter = LoopBuilder();
  inter.AddIntersection("I", {"b"}, {"b"});
  EXPECT_THAT(BuildError(inter), HasSubstr("both inner and approach"));
  MapBuilder station = LoopBuilder();
  station.AddStation("S", "b", 2);
  EXPECT_THAT(BuildError(station), HasSubstr("is a lane point, not park"));
  MapBuilder shelf = LoopBuilder();
  shelf.AddShelf("SH", {3, 3}, {2, 4});
  EXPECT_THAT(BuildError(shelf), HasSubstr("shelf 0 ('SH'): min"));
  MapBuilder flat = LoopBuilder();
  flat.AddZone("Flat", {{0, 0}, {1, 1}, {2, 2}});
  EXPECT_THAT(BuildError(flat), HasSubstr("area is zero"));
  MapBuilder dup = LoopBuilder();
  dup.AddPath("a", "b");
  EXPECT_THAT(BuildError(dup), HasSubstr("duplicate path"));
}

TEST(MapBuilderTest, RejectsRepeatedOrOverlappingIntersectionPointsAndSharedStations) {
  MapBuilder twice = LoopBuilder();
  twice.AddIntersection("I", {"b", "b"}, {"a"});
  EXPECT_THAT(BuildError(twice), HasSubstr("inner point 'b' is listed twice"));
  MapBuilder approach_twice = LoopBuilder();
  approach_twice.AddIntersection("I", {"b"}, {"a", "a"});
  EXPECT_THAT(BuildError(approach_twice), HasSubstr("approach point 'a' is listed twice"));
  MapBuilder other = LoopBuilder();
  other.AddIntersection("I1", {"b"}, {"a"});
  other.AddIntersection("I2", {"c"}, {"b"});
  EXPECT_THAT(BuildError(other), HasSubstr("approach point 'b' lies inside intersection 'I1'"));
  MapBuilder shared = LoopBuilder();
  shared.AddPoint("p", {8, 1}, PointKind::kPark);
  shared.AddPath("b", "p", std::nullopt, 0, true);
  shared.AddStation("S1", "p", 2);
  shared.AddStation("S2", "p", 2);
  EXPECT_THAT(BuildError(shared), HasSubstr("already holds station 'S1'"));
}

TEST(MapBuilderTest, RejectsSelfCrossingZonesAndZonesOffTheFloor) {
  MapBuilder bowtie = LoopBuilder();
  bowtie.AddZone("Bow", {{0, 0}, {4, 2}, {4, 0}, {0, 3}});
  EXPECT_THAT(BuildError(bowtie), HasSubstr("polygon crosses itself"));
  MapBuilder off = LoopBuilder();
  off.SetFloor({0, 0}, {10, 10});
  off.AddRectZone("Out", {5, 5}, {12, 8});
  EXPECT_THAT(BuildError(off), HasSubstr("vertex (12, 5) lies outside the floor"));
}

}  // namespace
}  // namespace dispatch::engine
