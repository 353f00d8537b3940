#include "engine/routing/cost_graph.h"

#include <gtest/gtest.h>

#include <numbers>

#include "engine/map/map_builder.h"
#include "routing_test_util.h"

namespace dispatch::engine {
namespace {

TEST(CostGraphTest, CsrListsEveryArcOnceByTailAndHead) {
  const CostGraph g = testing::RandomCostGraph(7, 50, 3.0);
  std::vector<int> out_seen(g.arc_count()), in_seen(g.arc_count());
  for (VertexId v = 0; v < 50; ++v) {
    for (std::int32_t id : g.out_arcs(v)) {
      EXPECT_EQ(g.arc(id).from, v);
      ++out_seen[static_cast<std::size_t>(id)];
    }
    for (std::int32_t id : g.in_arcs(v)) {
      EXPECT_EQ(g.arc(id).to, v);
      ++in_seen[static_cast<std::size_t>(id)];
    }
  }
  for (std::size_t i = 0; i < g.arc_count(); ++i) {
    EXPECT_EQ(out_seen[i], 1);
    EXPECT_EQ(in_seen[i], 1);
  }
}

TEST(CostGraphTest, CheapestArcPicksTheCheaperParallelArc) {
  const CostGraph g =
      CostGraph::Build(3, {{0, 1, 5.0}, {0, 1, 2.0}, {1, 2, 0.0}, {0, 1, 2.0}}).value();
  EXPECT_EQ(g.CheapestArc(0, 1), 1);
  EXPECT_EQ(g.CheapestArc(1, 2), 2);
  EXPECT_EQ(g.CheapestArc(2, 0), -1);
}

TEST(CostGraphTest, RejectsBadArcs) {
  EXPECT_FALSE(CostGraph::Build(2, {{0, 2, 1.0}}).ok());
  EXPECT_FALSE(CostGraph::Build(2, {{-1, 0, 1.0}}).ok());
  EXPECT_FALSE(CostGraph::Build(2, {{0, 1, -1.0}}).ok());
  EXPECT_FALSE(CostGraph::Build(2, {{0, 1, std::numeric_limits<double>::infinity()}}).ok());
  const auto nan = CostGraph::Build(2, {{0, 1, std::nan("")}});
  ASSERT_FALSE(nan.ok());
  EXPECT_NE(nan.error().message.find("arc 0"), std::string::npos);
  EXPECT_TRUE(CostGraph::Build(0, {}).ok());
}

// S(-10,0) -> A(0,0) one-way; A <-> B(10,0) slow lane; A -> T(-5,0): a U-turn at A.
// A -> C(0,10): a left turn.
std::shared_ptr<const WarehouseMap> TurnMap() {
  MapBuilder b("turns");
  b.AddRectZone("floor", {-20, -20}, {20, 20});
  b.AddPoint("S", {-10, 0}, PointKind::kLane);
  b.AddPoint("A", {0, 0}, PointKind::kLane);
  b.AddPoint("B", {10, 0}, PointKind::kLane);
  b.AddPoint("T", {-5, 0}, PointKind::kLane);
  b.AddPoint("C", {0, 10}, PointKind::kLane);
  b.AddPath("S", "A");
  b.AddPath("A", "B", std::nullopt, 0.5, true);
  b.AddPath("A", "T");
  b.AddPath("A", "C");
  return std::make_shared<const WarehouseMap>(b.Build().value());
}

TEST(MapCostGraphTest, ArcCostIsLengthOverCappedSpeed) {
  const auto map = TurnMap();
  RouteTableOptions options;
  options.speed = 2.0;
  const MapCostGraph g = BuildMapCostGraph(*map, options).value();
  EXPECT_FALSE(g.expanded);
  ASSERT_EQ(g.graph.vertex_count(), map->point_count());
  ASSERT_EQ(g.graph.arc_count(), map->arcs().size());
  for (std::size_t i = 0; i < map->arcs().size(); ++i) {
    const Arc& a = map->arcs()[i];
    EXPECT_EQ(g.map_arc[i], static_cast<ArcId>(i));
    EXPECT_DOUBLE_EQ(g.graph.arcs()[i].cost, a.length / (a.max_speed > 0 ? 0.5 : 2.0));
  }
}

TEST(MapCostGraphTest, ExpandedGraphChargesTurnsByAngle) {
  const auto map = TurnMap();
  RouteTableOptions options;
  options.turn_penalty_s = 3.0;
  const MapCostGraph g = BuildMapCostGraph(*map, options).value();
  ASSERT_TRUE(g.expanded);
  const std::size_t pc = map->point_count();
  EXPECT_EQ(g.graph.vertex_count(), pc + map->arcs().size());
  const ArcId sa = *map->FindArc(*map->FindPoint("S"), *map->FindPoint("A"));
  const ArcId at = *map->FindArc(*map->FindPoint("A"), *map->FindPoint("T"));
  const ArcId ac = *map->FindArc(*map->FindPoint("A"), *map->FindPoint("C"));
  const ArcId ab = *map->FindArc(*map->FindPoint("A"), *map->FindPoint("B"));
  EXPECT_NEAR(TurnAngle(*map, sa, at), std::numbers::pi, 1e-12);
  EXPECT_NEAR(TurnAngle(*map, sa, ac), std::numbers::pi / 2, 1e-12);
  EXPECT_NEAR(TurnAngle(*map, sa, ab), 0.0, 1e-12);
  auto cost = [&](ArcId from, ArcId to) {
    const auto v = static_cast<VertexId>(pc) + from;
    const std::int32_t id = g.graph.CheapestArc(v, static_cast<VertexId>(pc) + to);
    EXPECT_GE(id, 0);
    EXPECT_EQ(g.map_arc[static_cast<std::size_t>(id)], to);
    return g.graph.arc(id).cost;
  };
  EXPECT_NEAR(cost(sa, at), 5.0 + 6.0, 1e-9);   // U-turn: 2 x penalty
  EXPECT_NEAR(cost(sa, ac), 10.0 + 3.0, 1e-9);  // 90 degrees: 1 x penalty
  EXPECT_NEAR(cost(sa, ab), 20.0, 1e-9);        // straight, slow lane (0.5 m/s)
  // Point vertices start without heading: S -> arc S->A costs the arc only.
  const std::int32_t first = g.graph.CheapestArc(*map->FindPoint("S"), static_cast<VertexId>(pc) + sa);
  ASSERT_GE(first, 0);
  EXPECT_NEAR(g.graph.arc(first).cost, 10.0, 1e-9);
  EXPECT_EQ(g.TargetVertices(*map, *map->FindPoint("A")).size(), 3u);  // A, S->A, B->A
}

TEST(MapCostGraphTest, RejectsBadOptions) {
  const auto map = TurnMap();
  RouteTableOptions options;
  options.speed = 0.0;
  EXPECT_EQ(BuildMapCostGraph(*map, options).error().code, ErrorCode::kInvalidArgument);
  options.speed = 1.0;
  options.turn_penalty_s = -1.0;
  EXPECT_EQ(BuildMapCostGraph(*map, options).error().code, ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace dispatch::engine
