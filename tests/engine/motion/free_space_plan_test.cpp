// A four-wheel-steer robot's plan: the road graph outside the free-space regions, the hybrid
// A* inside them, with headings and modes, timed on from the graph's times.
#include "engine/motion/free_space_plan.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <set>

#include "engine/map/map_builder.h"
#include "engine/motion/free_space_grid.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine {
namespace {

// A corridor bay (x 2-8 m, y 0.1-1.5 m) with a crab slot beside it (x 4-5, y 1.5-2.15: 1.0 m by
// 0.65 m, the robot 0.8 by 0.5), as the narrow floor's. The road graph: park - w - E - m1 - m2 -
// X - o - D along y = 0.8, E to X inside the bay, and the slot's pick P joined to m1 below it.
// Lanes carry every robot; a 4WIS robot is planned by the hybrid A* between E, P and X.
class FreeSpacePlanTest : public ::testing::Test {
 protected:
  void SetUp() override {
    MapBuilder b("bay");
    b.SetFloor({0, 0}, {12, 3});
    b.AddRectZone("z", {0, 0}, {12, 3});
    b.AddPoint("park", {0.5, 0.8}, PointKind::kPark);
    b.AddPoint("w", {1.5, 0.8}, PointKind::kLane);
    b.AddPoint("E", {2.8, 0.8}, PointKind::kLane);
    b.AddPoint("P", {4.5, 1.825}, PointKind::kPick);
    b.AddPoint("m1", {4.5, 0.8}, PointKind::kLane);
    b.AddPoint("m2", {5.8, 0.8}, PointKind::kLane);
    b.AddPoint("X", {7.2, 0.8}, PointKind::kLane);
    b.AddPoint("o", {8.8, 0.8}, PointKind::kLane);
    b.AddPoint("D", {10.0, 0.8}, PointKind::kDrop);
    for (auto [a, c] : {std::pair{"park", "w"}, {"w", "E"}, {"E", "m1"}, {"m1", "m2"}, {"m2", "X"}, {"X", "o"},
                        {"o", "D"}, {"m1", "P"}}) {
      b.AddPath(a, c, std::nullopt, 0.0, true);
    }
    b.AddFreeSpace("bay", {{2, 0.1}, {8, 0.1}, {8, 1.5}, {5, 1.5}, {5, 2.15}, {4, 2.15}, {4, 1.5}, {2, 1.5}});
    MapBuildOptions options;
    options.check_service_connectivity = false;
    auto map = b.Build(options);
    ASSERT_TRUE(map.ok()) << map.error().message;
    map_ = std::make_shared<const WarehouseMap>(std::move(map).value());
    auto routes = MakeRouteTable(map_, {});
    ASSERT_TRUE(routes.ok()) << routes.error().message;
    routes_ = std::move(routes).value();
    auto motion = FreeSpaceMotion::Create(map_);
    ASSERT_TRUE(motion.ok()) << motion.error().message;
    motion_ = std::make_unique<FreeSpaceMotion>(std::move(motion).value());
  }
  PointId P(const char* name) const { return *map_->FindPoint(name); }
  Plan GraphPlan(double work = 3.0) const {
    auto plan = BuildPlan(*map_, *routes_, P("park"), 10.0, 1.0, {{{P("P")}, P("D"), work, 0.0}});
    EXPECT_TRUE(plan.ok()) << plan.error().message;
    return std::move(plan).value();
  }
  std::size_t IndexOf(const Plan& plan, const char* name) const {
    for (std::size_t k = 0; k < plan.waypoints.size(); ++k) {
      if (plan.waypoints[k].point == P(name) && plan.waypoints[k].action != WaypointAction::kMove) return k;
    }
    return plan.waypoints.size();
  }

  std::shared_ptr<const WarehouseMap> map_;
  std::shared_ptr<const RouteTable> routes_;
  std::unique_ptr<FreeSpaceMotion> motion_;
};

TEST_F(FreeSpacePlanTest, TheRobotCrabsIntoTheSlotWithTheTasksHeadingAndLeavesAlongItsLane) {
  const Plan graph = GraphPlan();
  std::vector<std::string> names;
  for (const Waypoint& w : graph.waypoints) names.push_back(map_->point(w.point).name);
  ASSERT_EQ(names, (std::vector<std::string>{"park", "w", "E", "m1", "P", "m1", "m2", "X", "o", "D"}));
  EXPECT_EQ(motion_->RegionOf(P("E")), 0u);
  EXPECT_EQ(motion_->RegionOf(P("w")), static_cast<std::size_t>(-1));

  // The pick faces east, as the slot demands (the arc m1 -> P would have the robot face north).
  auto refined = motion_->Refine(graph, 1.0, {{4, 0.0}});
  ASSERT_TRUE(refined.ok()) << refined.error().message;
  const std::vector<Waypoint>& w = refined->waypoints;
  ASSERT_GT(w.size(), graph.waypoints.size());

  // Outside the bay: unchanged before it, shifted by one amount after it.
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(w[k].point, graph.waypoints[k].point);
    EXPECT_DOUBLE_EQ(w[k].eta, graph.waypoints[k].eta);
    EXPECT_FALSE(w[k].mode.has_value());
  }
  EXPECT_FALSE(w[0].heading.has_value());
  EXPECT_NEAR(*w[2].heading, 0.0, 1e-9);  // E, entered heading east
  const double shift = w.back().eta - graph.waypoints.back().eta;
  EXPECT_NEAR(w[w.size() - 2].eta - graph.waypoints[8].eta, shift, 1e-9);  // o
  EXPECT_EQ(w.back().point, P("D"));
  EXPECT_EQ(w.back().action, WaypointAction::kDrop);

  // The pick: its point, place, work and heading; reached by a crab (the only way in).
  const std::size_t pick = IndexOf(*refined, "P");
  ASSERT_LT(pick, w.size());
  EXPECT_TRUE(w[pick].xy.isApprox(map_->point(P("P")).position));
  EXPECT_EQ(w[pick].dwell, 3.0);
  EXPECT_NEAR(*w[pick].heading, 0.0, 1e-9);
  std::set<MotionMode> modes;
  for (std::size_t k = 3; k <= pick; ++k) modes.insert(w[k].mode.value());
  EXPECT_TRUE(modes.count(MotionMode::kCrabLeft)) << "no crab into the slot";
  // X, where it leaves the bay: facing down the lane to o (east).
  std::size_t x = pick + 1;
  while (x < w.size() && w[x].point != P("X")) ++x;
  while (x + 1 < w.size() && w[x + 1].point == P("X")) ++x;  // the poses nearest X end at X itself
  ASSERT_LT(x, w.size());
  EXPECT_TRUE(w[x].xy.isApprox(map_->point(P("X")).position));
  EXPECT_NEAR(*w[x].heading, 0.0, 1e-9);

  // The traffic gate's view: the graph route's points in its order, one arc at a time.
  std::vector<std::string> passed;
  for (std::size_t k = 0; k < w.size(); ++k) {
    if (k > 0 && w[k].point != w[k - 1].point) {
      EXPECT_TRUE(map_->FindArc(w[k - 1].point, w[k].point).has_value()) << k;
    }
    if (passed.empty() || passed.back() != map_->point(w[k].point).name) passed.push_back(map_->point(w[k].point).name);
  }
  EXPECT_EQ(passed, names);

  // Every pose inside the bay fits it; times grow by the motion at 1 m/s (spins at 1 rad/s),
  // the pick's work included; sequences run on.
  auto grid = FreeSpaceGrid(*map_, 0, 0.1);
  ASSERT_TRUE(grid.ok());
  FootprintChecker checker(*grid, motion_->options().footprint);
  for (std::size_t k = 0; k < w.size(); ++k) {
    EXPECT_EQ(w[k].seq, static_cast<int>(k));
    if (k > 0) {
      EXPECT_GE(w[k].eta + 1e-9, w[k - 1].departure()) << k;
      // A straight or crab step takes its distance; no step is faster than that.
      EXPECT_GE(w[k].eta - w[k - 1].departure() + 1e-9, (w[k].xy - w[k - 1].xy).norm()) << k;
    }
    if (w[k].heading && motion_->RegionOf(w[k].point) == 0u) {
      EXPECT_FALSE(checker.Collides({w[k].xy.x(), w[k].xy.y(), *w[k].heading})) << k;
    }
  }
  EXPECT_GT(shift, 0.0);  // the crab's manoeuvre is longer than the lane's straight 2 m
}

TEST_F(FreeSpacePlanTest, APlanThatTouchesNoRegionComesBackUnchanged) {
  auto plan = BuildPlan(*map_, *routes_, P("park"), 0.0, 1.0, {{{P("w")}, P("park"), 2.0, 0.0}});
  // w is a lane, not a pick: BuildPlan does not mind the kinds.
  ASSERT_TRUE(plan.ok()) << plan.error().message;
  auto refined = motion_->Refine(*plan, 1.0);
  ASSERT_TRUE(refined.ok()) << refined.error().message;
  ASSERT_EQ(refined->waypoints.size(), plan->waypoints.size());
  for (std::size_t k = 0; k < plan->waypoints.size(); ++k) {
    EXPECT_EQ(refined->waypoints[k].point, plan->waypoints[k].point);
    EXPECT_EQ(refined->waypoints[k].eta, plan->waypoints[k].eta);
    EXPECT_FALSE(refined->waypoints[k].heading.has_value());
  }
}

TEST_F(FreeSpacePlanTest, ErrorsNameTheRegionAndThePoints) {
  const Plan graph = GraphPlan();
  // The graph's own heading at the pick (north, up the arc from m1) does not fit the slot.
  auto skewed = motion_->Refine(graph, 1.0);
  ASSERT_FALSE(skewed.ok());
  EXPECT_EQ(skewed.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(skewed.error().message.find("free space 'bay': from 'E'"), std::string::npos) << skewed.error().message;
  EXPECT_NE(skewed.error().message.find("to 'P'"), std::string::npos) << skewed.error().message;
  // The baseline robot (no crab, no spin) cannot park in the slot.
  FreeSpaceMotionOptions car;
  car.search.allow_crab = false;
  car.search.allow_spin = false;
  car.search.limits.max_expansions = 20000;
  auto baseline = FreeSpaceMotion::Create(map_, car);
  ASSERT_TRUE(baseline.ok());
  auto parked = baseline->Refine(graph, 1.0, {{4, 0.0}});
  ASSERT_FALSE(parked.ok());
  EXPECT_TRUE(parked.error().code == ErrorCode::kUnreachable || parked.error().code == ErrorCode::kFailedPrecondition)
      << parked.error().message;
  EXPECT_NE(parked.error().message.find("free space 'bay'"), std::string::npos);
  EXPECT_EQ(motion_->Refine(graph, 0.0).error().code, ErrorCode::kInvalidArgument);
  FreeSpaceMotionOptions bad;
  bad.spin_rate = 0.0;
  EXPECT_EQ(FreeSpaceMotion::Create(map_, bad).error().code, ErrorCode::kInvalidArgument);
  EXPECT_EQ(FreeSpaceMotion::Create(nullptr).error().code, ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace dispatch::engine
