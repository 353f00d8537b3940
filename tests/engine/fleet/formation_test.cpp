#include "engine/fleet/formation.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <memory>
#include <numbers>

#include "engine/map/chu2024_floor.h"
#include "engine/map/map_builder.h"

namespace dispatch::engine {
namespace {

constexpr double kTol = 1e-9;

// Checks the rigid triangle at every waypoint from the rendezvous on: distances to the
// centre equal D_f, pairwise distances equal the side, ETAs are shared.
void ExpectRigidAfterRendezvous(const FormationPlans& f, const FormationOptions& options = {}) {
  const double d_f = FormationRadius(options);
  ASSERT_EQ(f.members.size(), 3u);
  ASSERT_EQ(f.formation_start.size(), 3u);
  const std::size_t n = f.centre.waypoints.size();
  ASSERT_GT(n, 0u);
  EXPECT_EQ(f.centre.waypoints.front().eta, f.rendezvous_time);
  for (std::size_t i = 0; i < 3; ++i) {
    ASSERT_EQ(f.members[i].waypoints.size(), f.formation_start[i] + n);
  }
  for (std::size_t k = 0; k < n; ++k) {
    const Waypoint& c = f.centre.waypoints[k];
    const Waypoint* m[3];
    for (std::size_t i = 0; i < 3; ++i) m[i] = &f.members[i].waypoints[f.formation_start[i] + k];
    for (std::size_t i = 0; i < 3; ++i) {
      EXPECT_NEAR((m[i]->xy - c.xy).norm(), d_f, kTol) << "waypoint " << k << " member " << i;
      EXPECT_NEAR((m[i]->xy - m[(i + 1) % 3]->xy).norm(), options.side, kTol) << k;
      EXPECT_EQ(m[i]->eta, c.eta) << k;
      EXPECT_EQ(m[i]->dwell, c.dwell) << k;
      EXPECT_EQ(m[i]->action, c.action) << k;
    }
  }
}

TEST(FormationOffsetsTest, EquilateralTriangleAroundTheCentre) {
  const double d_f = FormationRadius();
  EXPECT_NEAR(d_f, 0.4 / std::sqrt(3.0), 1e-12);
  for (double heading : {0.0, 0.3, std::numbers::pi / 2, -2.0}) {
    const FormationOffsetArray o = FormationOffsets(heading);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(o[i].norm(), d_f, 1e-12);
      EXPECT_NEAR((o[i] - o[(i + 1) % 3]).norm(), 0.4, 1e-12);
      // eq. (9): atan2 of the offset is theta_i = heading + i * 2 pi / 3.
      const double theta = std::atan2(o[i].y(), o[i].x());
      EXPECT_NEAR(std::remainder(theta - heading - i * 2 * std::numbers::pi / 3,
                                 2 * std::numbers::pi),
                  0.0, 1e-12);
    }
    EXPECT_NEAR((o[0] + o[1] + o[2]).norm(), 0.0, 1e-12);  // centred
  }
  // Member 0 leads: it points along the heading.
  EXPECT_TRUE(FormationOffsets(std::numbers::pi / 2)[0].isApprox(Eigen::Vector2d(0, d_f)));
  FormationOptions wide;
  wide.side = 1.0;
  EXPECT_NEAR(FormationOffsets(0.0, wide)[1].norm(), 1.0 / std::sqrt(3.0), 1e-12);
}

// An L-shaped floor: the centre goes east from the pick A to B, turns left (+90 degrees) and
// goes north to the drop C. Members start west of A at different distances.
class LFormationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    MapBuilder b("L");
    b.AddRectZone("floor", {-20, -5}, {20, 20});
    b.AddPoint("A", {0, 0}, PointKind::kPick);
    b.AddPoint("B", {10, 0}, PointKind::kLane);
    b.AddPoint("C", {10, 10}, PointKind::kDrop);
    b.AddPoint("M1", {-2, 0}, PointKind::kLane);
    b.AddPoint("M2", {-6, 0}, PointKind::kLane);
    b.AddPoint("M3", {-12, 0}, PointKind::kLane);
    b.AddPath("A", "B", std::nullopt, 0.0, true);
    b.AddPath("B", "C", std::nullopt, 0.0, true);
    b.AddPath("M3", "M2");
    b.AddPath("M2", "M1");
    b.AddPath("M1", "A");
    b.AddPath("A", "M3", 20.0);
    map_ = std::make_shared<const WarehouseMap>(b.Build().value());
    routes_ = MakeRouteTable(map_, {}).value();
  }
  PointId Id(const char* name) const { return *map_->FindPoint(name); }
  std::shared_ptr<const WarehouseMap> map_;
  std::unique_ptr<RouteTable> routes_;
};

TEST_F(LFormationTest, RendezvousWaitsForTheSlowestThenMovesRigidly) {
  const double v = 2.0, t_w = 3.0, t_drop = 1.5, t0 = 5.0;
  const PlanTask task{{Id("A")}, Id("C"), t_w, t_drop};
  const Result<FormationPlans> f =
      BuildFormationPlans(*map_, *routes_, {Id("M1"), Id("M2"), Id("M3")}, t0, v, task);
  ASSERT_TRUE(f.ok()) << f.error().message;
  const double d_f = FormationRadius();
  // The slowest member (M3, 12 m away) arrives at A at t0 + 6 s, then its slot.
  EXPECT_NEAR(f->rendezvous_time, t0 + 12.0 / v + d_f / v, kTol);
  for (std::size_t i = 0; i < 3; ++i) {
    const Waypoint& slot = f->members[i].waypoints[f->formation_start[i] - 1];
    EXPECT_EQ(slot.action, WaypointAction::kWait);
    EXPECT_NEAR(slot.departure(), f->rendezvous_time, kTol);
    // Members wait in their slots: the same place as their first formation waypoint.
    EXPECT_EQ(slot.xy, f->members[i].waypoints[f->formation_start[i]].xy);
    EXPECT_EQ(f->members[i].PositionAt(slot.eta), slot.xy);
    EXPECT_EQ(f->members[i].PositionAt(slot.eta + slot.dwell / 2), slot.xy);
  }
  EXPECT_NEAR(f->members[0].waypoints[f->formation_start[0] - 1].dwell, (12.0 - 2.0) / v, kTol);
  ExpectRigidAfterRendezvous(*f);

  // Heading east until B, north after it: the triangle turns by +90 degrees at B.
  const FormationOffsetArray east = FormationOffsets(0.0);
  const FormationOffsetArray north = FormationOffsets(std::numbers::pi / 2);
  const Plan& c = f->centre;
  const std::size_t first = 0, last = c.waypoints.size() - 1;
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& w = f->members[i].waypoints;
    const std::size_t s = f->formation_start[i];
    EXPECT_TRUE((w[s + first].xy - c.waypoints[first].xy).isApprox(east[i]));
    EXPECT_TRUE((w[s + last].xy - c.waypoints[last].xy).isApprox(north[i]));
    // The rotation is the 90-degree rotation of the offsets.
    EXPECT_TRUE((Eigen::Rotation2Dd(std::numbers::pi / 2) * east[i]).isApprox(north[i]));
  }
  EXPECT_TRUE(f->members[0].waypoints.back().xy.isApprox(Eigen::Vector2d(10, 10 + d_f)));
  // Work at A, 10 m east, rotation at B (D_f * pi/2 at v), 10 m north, the drop's work at C.
  const double rotation = d_f * std::numbers::pi / 2 / v;
  ASSERT_EQ(c.waypoints.back().action, WaypointAction::kDrop);
  EXPECT_NEAR(c.waypoints.back().eta,
              f->rendezvous_time + t_w + 10.0 / v + rotation + 10.0 / v, kTol);
  EXPECT_NEAR(c.end_time(), f->rendezvous_time + t_w + 20.0 / v + rotation + t_drop, kTol);
  // The rotation at B happens in place: the centre holds B while the members turn.
  int turns = 0;
  for (std::size_t k = 1; k < c.waypoints.size(); ++k) {
    if (c.waypoints[k].point == Id("B") && c.waypoints[k - 1].point == Id("B")) ++turns;
  }
  EXPECT_EQ(turns, 2);  // 90 degrees in steps of at most 45
}

TEST_F(LFormationTest, RejectsWrongTeamSizeAndUnreachableMembers) {
  const PlanTask task{{Id("A")}, Id("C"), 1.0};
  const auto two = BuildFormationPlans(*map_, *routes_, {Id("M1"), Id("M2")}, 0, 1.0, task);
  ASSERT_FALSE(two.ok());
  EXPECT_EQ(two.error().code, ErrorCode::kInvalidArgument);
  const auto bad = BuildFormationPlans(*map_, *routes_, {Id("M1"), Id("M2"), 9999}, 0, 1.0, task);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("member 2"), std::string::npos) << bad.error().message;
}

// Seed table 1, tasks 1 and 3 on the Chu2024 floor with robots R1..R3 (stations P1..P3).
// Task 3 visits the pick dock (14, 16.5): the centre reverses there, a 180-degree rotation.
class Chu2024FormationTest : public ::testing::TestWithParam<int> {};

TEST_P(Chu2024FormationTest, SeedTaskStaysRigidAndTurnsWithTheRoute) {
  const auto map = std::make_shared<const WarehouseMap>(BuildChu2024Floor().value());
  const auto routes = MakeRouteTable(map, {}).value();
  auto pick = [&](double x, double y) { return map->NearestPoint({x, y}, PointKind::kPick); };
  const PlanTask task =
      GetParam() == 1
          ? PlanTask{{pick(19, 17), pick(20.5, 10.5)},
                     map->NearestPoint({6.5, 2.75}, PointKind::kDrop), 5.0}
          : PlanTask{{pick(4, 5), pick(14, 16.5), pick(30.5, 5)},
                     map->NearestPoint({2.25, 6.5}, PointKind::kDrop), 5.0};
  const std::vector<PointId> starts = {map->FindPoint("park-P1").value(),
                                       map->FindPoint("park-P2").value(),
                                       map->FindPoint("park-P3").value()};
  const Result<FormationPlans> f = BuildFormationPlans(*map, *routes, starts, 0.0, 1.0, task);
  ASSERT_TRUE(f.ok()) << f.error().message;
  ExpectRigidAfterRendezvous(*f);
  // Between two waypoints at different places the triangle is aligned with the segment.
  const auto& c = f->centre.waypoints;
  int segments = 0;
  for (std::size_t k = 0; k + 1 < c.size(); ++k) {
    const Eigen::Vector2d d = c[k + 1].xy - c[k].xy;
    if (d.norm() < 1e-9) continue;
    ++segments;
    const FormationOffsetArray o = FormationOffsets(std::atan2(d.y(), d.x()));
    for (std::size_t i = 0; i < 3; ++i) {
      const auto& w = f->members[i].waypoints;
      EXPECT_TRUE((w[f->formation_start[i] + k].xy - c[k].xy).isApprox(o[i], 1e-9)) << k;
      EXPECT_TRUE((w[f->formation_start[i] + k + 1].xy - c[k + 1].xy).isApprox(o[i], 1e-9)) << k;
    }
  }
  EXPECT_GT(segments, 5);
  // The structure turned at least once; in the dock task it reverses (two half-turns).
  double turned = 0.0;
  for (std::size_t k = 1; k < f->headings.size(); ++k) {
    turned += std::abs(std::remainder(f->headings[k] - f->headings[k - 1], 2 * std::numbers::pi));
  }
  EXPECT_GE(turned, GetParam() == 1 ? std::numbers::pi / 2 : 2 * std::numbers::pi - 1e-9);
  // Every member's plan has monotone ETAs.
  for (const Plan& p : f->members) {
    for (std::size_t k = 1; k < p.waypoints.size(); ++k) {
      EXPECT_GE(p.waypoints[k].eta, p.waypoints[k - 1].departure() - kTol);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Table1, Chu2024FormationTest, ::testing::Values(1, 3));

}  // namespace
}  // namespace dispatch::engine
