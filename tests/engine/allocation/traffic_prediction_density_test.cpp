// TrafficPredictor's density on hand-made plans (Chu2024 eqs. (6)-(8)): per-zone peaks over
// the other robots, the flow of a sampled plan through a crowded zone. The counts' model test
// and SamplePlan are in traffic_prediction_test.cpp.
#include "engine/allocation/traffic_prediction.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "engine/map/chu2024_floor.h"
#include "engine/map/map_builder.h"

namespace dispatch::engine {
namespace {

// --- Density ------------------------------------------------------------------------------

Plan ParkedPlan(const Eigen::Vector2d& xy, double from, double until) {
  Plan plan;
  plan.waypoints = {{0, kNoPoint, xy, from, WaypointAction::kPark, until - from, {}, {}}};
  return plan;
}

TEST(TrafficPredictionDensityTest, PeaksPerZoneOverOtherRobotsOnly) {
  const WarehouseMap map = BuildChu2024Floor().value();
  TrafficPredictor pred(map, {});
  const ZoneId z1 = map.FindZone("Z1").value(), z2 = map.FindZone("Z2").value();
  const ZoneId z3 = map.FindZone("Z3").value();
  // By hand from chu2024_floor.md: floor x in [-2.5, 37], y in [-2, 25.5], cuts at x = 12.25,
  // 22.25 and y = 11.75.
  const double s1 = (12.25 + 2.5) * (11.75 + 2.0);    // 202.8125 m^2
  const double s2 = (22.25 - 12.25) * (11.75 + 2.0);  // 137.5 m^2
  ASSERT_NEAR(map.zones()[static_cast<std::size_t>(z1)].area, s1, 1e-9);
  ASSERT_NEAR(map.zones()[static_cast<std::size_t>(z2)].area, s2, 1e-9);

  // R1 and R2 park in Z1 (R1 leaves for Z4 at t = 200), R4 parks in Z2, and the bidder R3
  // itself parks in Z1: it must not count itself.
  Plan r1 = ParkedPlan({5, 5}, 0.0, 200.0);
  r1.waypoints.push_back({1, kNoPoint, {5, 20}, 210.0, WaypointAction::kPark, 790.0, {}, {}});
  pred.SetPlan("R1", r1);
  pred.SetPlan("R2", ParkedPlan({6, 5}, 0.0, 1000.0));
  pred.SetPlan("R3", ParkedPlan({7, 5}, 0.0, 1000.0));
  pred.SetPlan("R4", ParkedPlan({15, 5}, 0.0, 1000.0));

  // The candidate route: Z1 at 100 (R1, R2), Z2 at 110 (R4), Z3 at 120 (nobody), Z1 again at
  // 300 (R2 only), and a sample off the floor (no zone).
  const std::vector<RouteSample> route = {
      {{4, 4}, 100.0}, {{15, 4}, 110.0}, {{30, 4}, 120.0}, {{4, 6}, 300.0}, {{50, 50}, 310.0}};
  const DensityTerm d = pred.Density(route, "R3");
  const std::vector<std::pair<ZoneId, int>> want_peaks = {{z1, 2}, {z2, 1}, {z3, 0}};
  EXPECT_EQ(d.peaks, want_peaks);
  EXPECT_NEAR(d.flow, 2.0 / s1 + 1.0 / s2, 1e-12);  // eqs. (6)-(8)

  // Without excluding anyone R3 counts too.
  const DensityTerm all = pred.Density(route, "");
  EXPECT_EQ(all.peaks.front(), (std::pair<ZoneId, int>{z1, 3}));
  EXPECT_NEAR(all.flow, 3.0 / s1 + 1.0 / s2, 1e-12);

  // An hour later every plan has ended: the same zones with 0, F = 0.
  std::vector<RouteSample> later = route;
  for (RouteSample& s : later) s.t += 3600.0;
  const DensityTerm empty = pred.Density(later, "R3");
  const std::vector<std::pair<ZoneId, int>> zero_peaks = {{z1, 0}, {z2, 0}, {z3, 0}};
  EXPECT_EQ(empty.peaks, zero_peaks);
  EXPECT_EQ(empty.flow, 0.0);

  // No samples: nothing.
  EXPECT_TRUE(pred.Density({}, "R3").peaks.empty());

  // Removing R2 drops Z1's peak to R1's 1.
  pred.RemovePlan("R2");
  EXPECT_EQ(pred.Density(route, "R3").peaks.front(), (std::pair<ZoneId, int>{z1, 1}));
}

TEST(TrafficPredictionDensityTest, SampledPlanThroughACrowdedZone) {
  const WarehouseMap map = BuildChu2024Floor().value();
  TrafficPredictor pred(map, {});
  const ZoneId z1 = map.FindZone("Z1").value(), z2 = map.FindZone("Z2").value();
  pred.SetPlan("A", ParkedPlan({5, 5}, 0.0, 100.0));
  pred.SetPlan("B", ParkedPlan({6, 5}, 0.0, 100.0));
  // The bidder drives from (2, 4) in Z1 to (20, 4) in Z2, 1 m/s from t = 10.
  Plan candidate;
  candidate.waypoints = {{0, kNoPoint, {2, 4}, 10.0, WaypointAction::kMove, 0.0, {}, {}},
                         {1, kNoPoint, {20, 4}, 28.0, WaypointAction::kDrop, 5.0, {}, {}}};
  const DensityTerm d = pred.Density(SamplePlan(candidate, 1.0), "C");
  const std::vector<std::pair<ZoneId, int>> want = {{z1, 2}, {z2, 0}};
  EXPECT_EQ(d.peaks, want);
  EXPECT_NEAR(d.flow, 2.0 / map.zones()[static_cast<std::size_t>(z1)].area, 1e-12);
}

}  // namespace
}  // namespace dispatch::engine
