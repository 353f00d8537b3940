#include "engine/routing/floyd_route_table.h"

#include <gtest/gtest.h>

#include "routing_test_util.h"

namespace dispatch::engine {
namespace {

using testing::CostsAgree;
using testing::ExpectValidRoute;
using testing::RandomMap;
using testing::ReferenceCosts;

struct MapCase {
  unsigned seed;
  int side;
  double penalty;
  RouteTableMethod method;
};

class FloydRouteTableModelTest : public ::testing::TestWithParam<MapCase> {};

TEST_P(FloydRouteTableModelTest, MatchesReferenceDijkstraAndPathsAreValid) {
  const MapCase c = GetParam();
  const auto map = RandomMap(c.seed, c.side);
  RouteTableOptions options;
  options.speed = 1.5;
  options.turn_penalty_s = c.penalty;
  options.method = c.method;
  auto built = FloydRouteTable::Build(map, options);
  ASSERT_TRUE(built.ok()) << built.error().message;
  const FloydRouteTable& table = *built.value();
  EXPECT_EQ(table.point_count(), map->point_count());
  EXPECT_EQ(table.method(), c.method == RouteTableMethod::kDijkstra ? "dijkstra" : "floyd");
  EXPECT_EQ(table.build_info().turn_expanded, c.penalty > 0);
  const auto n = static_cast<PointId>(map->point_count());
  int unreachable = 0;
  for (PointId u = 0; u < n; ++u) {
    const std::vector<double> ref = ReferenceCosts(*map, u, options.speed, c.penalty);
    for (PointId v = 0; v < n; ++v) {
      ASSERT_TRUE(CostsAgree(ref[static_cast<std::size_t>(v)], table.Cost(u, v)))
          << u << " -> " << v << ": " << ref[static_cast<std::size_t>(v)] << " vs "
          << table.Cost(u, v);
      unreachable += std::isinf(ref[static_cast<std::size_t>(v)]);
      ExpectValidRoute(*map, table, u, v, options.speed, c.penalty);
      if (::testing::Test::HasFatalFailure()) return;
    }
  }
  EXPECT_GT(unreachable, 0);  // one-way lanes leave some pairs unreachable
}

INSTANTIATE_TEST_SUITE_P(
    RandomMaps, FloydRouteTableModelTest,
    ::testing::Values(MapCase{1, 6, 0.0, RouteTableMethod::kFloyd},
                      MapCase{2, 9, 0.0, RouteTableMethod::kFloyd},
                      MapCase{3, 9, 0.0, RouteTableMethod::kDijkstra},
                      MapCase{4, 7, 2.0, RouteTableMethod::kFloyd},
                      MapCase{5, 8, 0.7, RouteTableMethod::kDijkstra},
                      MapCase{6, 10, 5.0, RouteTableMethod::kFloyd}),
    [](const ::testing::TestParamInfo<MapCase>& info) {
      return "seed" + std::to_string(info.param.seed) + "_side" + std::to_string(info.param.side) +
             (info.param.penalty > 0 ? "_turns" : "") +
             (info.param.method == RouteTableMethod::kDijkstra ? "_dijkstra" : "_floyd");
    });

// S(0,0) -> X(10,0) -> T(20,0) is straight but X -> T is a 14 m curved lane; the detour
// X -> W(15,4) -> T is 12.8 m but turns 38.7 + 77.3 degrees.
std::shared_ptr<const WarehouseMap> DetourMap() {
  MapBuilder b("detour");
  b.AddRectZone("floor", {-1, -10}, {30, 10});
  b.AddPoint("S", {0, 0}, PointKind::kLane);
  b.AddPoint("X", {10, 0}, PointKind::kLane);
  b.AddPoint("T", {20, 0}, PointKind::kLane);
  b.AddPoint("W", {15, 4}, PointKind::kLane);
  b.AddPath("S", "X");
  b.AddPath("X", "T", 14.0);
  b.AddPath("X", "W");
  b.AddPath("W", "T");
  return std::make_shared<const WarehouseMap>(b.Build().value());
}

TEST(FloydRouteTableTest, TurnPenaltyMakesTheLongerStraightRouteWin) {
  const auto map = DetourMap();
  const PointId s = *map->FindPoint("S"), t = *map->FindPoint("T");
  const PointId x = *map->FindPoint("X"), w = *map->FindPoint("W");
  const double detour = 10.0 + 2 * std::sqrt(41.0);
  RouteTableOptions options;
  auto plain = FloydRouteTable::Build(map, options).value();
  EXPECT_NEAR(plain->Cost(s, t), detour, 1e-4);
  EXPECT_EQ(plain->Path(s, t).value().points, (std::vector<PointId>{s, x, w, t}));

  options.turn_penalty_s = 1.0;
  auto turning = FloydRouteTable::Build(map, options).value();
  EXPECT_NEAR(turning->Cost(s, t), 24.0, 1e-4);
  const Route r = turning->Path(s, t).value();
  EXPECT_EQ(r.points, (std::vector<PointId>{s, x, t}));
  EXPECT_NEAR(r.length, 24.0, 1e-9);
  EXPECT_EQ(turning->NextHop(s, t), x);
  // Starting at X there is no incoming heading: the detour only pays the turn at W
  // (77.3 degrees) and wins again.
  const double turn_wt = 2 * std::atan2(4.0, 5.0) / (std::numbers::pi / 2);
  EXPECT_NEAR(turning->Cost(x, t), 2 * std::sqrt(41.0) + turn_wt, 1e-4);
  EXPECT_EQ(turning->NextHop(x, t), w);
  EXPECT_EQ(turning->Cost(s, s), 0.0);
}

TEST(FloydRouteTableTest, ErrorsNameBothPoints) {
  const auto map = DetourMap();
  auto table = FloydRouteTable::Build(map, {}).value();
  const PointId s = *map->FindPoint("S"), t = *map->FindPoint("T");
  const auto unreachable = table->Path(t, s);
  ASSERT_FALSE(unreachable.ok());
  EXPECT_EQ(unreachable.error().code, ErrorCode::kUnreachable);
  EXPECT_NE(unreachable.error().message.find("'T'"), std::string::npos);
  EXPECT_NE(unreachable.error().message.find("'S'"), std::string::npos);
  EXPECT_TRUE(std::isinf(table->Cost(t, s)));
  EXPECT_EQ(table->NextHop(t, s), kNoPoint);
  const auto unknown = table->Path(s, 99);
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.error().code, ErrorCode::kNotFound);
  EXPECT_NE(unknown.error().message.find("'S'"), std::string::npos);
  EXPECT_NE(unknown.error().message.find("99"), std::string::npos);
  EXPECT_TRUE(std::isinf(table->Cost(-1, s)));
  EXPECT_EQ(table->NextHop(s, s), kNoPoint);
  const Route self = table->Path(s, s).value();
  EXPECT_EQ(self.points, std::vector<PointId>{s});
  EXPECT_TRUE(self.arcs.empty());
}

TEST(FloydRouteTableTest, CancelledBuildReturnsAnError) {
  const auto map = RandomMap(3, 12);
  for (RouteTableMethod method : {RouteTableMethod::kFloyd, RouteTableMethod::kDijkstra}) {
    RouteTableOptions options;
    options.method = method;
    auto built = FloydRouteTable::Build(map, options, [] { return true; });
    ASSERT_FALSE(built.ok());
    EXPECT_EQ(built.error().code, ErrorCode::kFailedPrecondition);
    auto made = MakeRouteTable(map, options, [] { return true; });
    ASSERT_FALSE(made.ok());
    EXPECT_EQ(made.error().code, ErrorCode::kFailedPrecondition);
  }
}

TEST(MakeRouteTableTest, PicksTheMethod) {
  const auto map = RandomMap(4, 8);
  RouteTableOptions options;
  EXPECT_EQ(MakeRouteTable(map, options).value()->method(), "floyd");
  options.method = RouteTableMethod::kDijkstra;
  EXPECT_EQ(MakeRouteTable(map, options).value()->method(), "dijkstra");
  options.method = RouteTableMethod::kLazy;
  EXPECT_EQ(MakeRouteTable(map, options).value()->method(), "lazy");
  options.method = RouteTableMethod::kAuto;
  const auto made = MakeRouteTable(map, options);
  const std::string chosen(made.value()->method());
  EXPECT_TRUE(chosen == "floyd" || chosen == "dijkstra") << chosen;
  // Above the threshold the lazy table is used whatever the method; with a turn penalty the
  // expanded vertex count (points + arcs) is what counts.
  options.method = RouteTableMethod::kFloyd;
  options.lazy_threshold_points = map->point_count();
  EXPECT_EQ(MakeRouteTable(map, options).value()->method(), "floyd");
  options.turn_penalty_s = 1.0;
  EXPECT_EQ(MakeRouteTable(map, options).value()->method(), "lazy");
  options.lazy_threshold_points = map->point_count() - 1;
  options.turn_penalty_s = 0.0;
  EXPECT_EQ(MakeRouteTable(map, options).value()->method(), "lazy");
}

TEST(MakeRouteTableTest, RejectsBadArguments) {
  EXPECT_EQ(MakeRouteTable(nullptr, {}).error().code, ErrorCode::kInvalidArgument);
  const auto map = RandomMap(5, 4);
  RouteTableOptions options;
  options.threads = 0;
  EXPECT_EQ(MakeRouteTable(map, options).error().code, ErrorCode::kInvalidArgument);
  options.threads = 2;
  options.speed = -1;
  EXPECT_EQ(MakeRouteTable(map, options).error().code, ErrorCode::kInvalidArgument);
}

TEST(ChooseDenseMethodTest, SparseLargeGraphsUseDijkstraTinyOnesFloyd) {
  EXPECT_EQ(ChooseDenseMethod(10, 30), RouteTableMethod::kFloyd);
  EXPECT_EQ(ChooseDenseMethod(4000, 4000 * 3), RouteTableMethod::kDijkstra);
  EXPECT_EQ(ChooseDenseMethod(2000, 2000 * 1000), RouteTableMethod::kFloyd);
}

}  // namespace
}  // namespace dispatch::engine
