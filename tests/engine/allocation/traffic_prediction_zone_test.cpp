// TrafficPredictor::ZoneAt (the zone grid): against a brute-force lookup on the
// Chu2024 floor, on non-rectangular and overlapping zones, at hairline borders and at LoRR
// scale. The prediction's counts, density and sampling are in traffic_prediction_test.cpp.
#include "engine/allocation/traffic_prediction.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "engine/map/chu2024_floor.h"
#include "engine/map/map_builder.h"
#include "tests/engine/allocation/zone_test_support.h"

namespace dispatch::engine {
namespace {

using testing_zones::BruteForceZone;
// Probe points: `n_random` uniform over the floor grown by `pad`, as many on cell corners of
// `cell` (from floor_min), and per zone edge its vertex plus `per_edge` points on the edge,
// each also shifted a hair (1e-12 .. 1e-4 m) off it.
std::vector<Eigen::Vector2d> ProbePoints(const WarehouseMap& map, int n_random, int per_edge,
                                         double pad, double cell, std::mt19937& rng) {
  std::vector<Eigen::Vector2d> pts;
  const Eigen::Vector2d lo = map.floor_min() - Eigen::Vector2d::Constant(pad);
  const Eigen::Vector2d hi = map.floor_max() + Eigen::Vector2d::Constant(pad);
  std::uniform_real_distribution<double> ux(lo.x(), hi.x()), uy(lo.y(), hi.y());
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (int i = 0; i < n_random; ++i) {
    pts.emplace_back(ux(rng), uy(rng));
    const Eigen::Vector2d p(ux(rng), uy(rng));
    pts.push_back(map.floor_min() +
                  cell * ((p - map.floor_min()) / cell).array().floor().matrix());
  }
  for (const Zone& zone : map.zones()) {
    const auto& poly = zone.polygon;
    for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
      pts.push_back(poly[i]);
      for (int k = 0; k < per_edge; ++k) {
        const Eigen::Vector2d p = poly[j] + u01(rng) * (poly[i] - poly[j]);
        pts.push_back(p);
        for (double off : {1e-12, 1e-10, 1e-8, 1e-6, 1e-4}) {
          pts.push_back(p + Eigen::Vector2d(off, 0));
          pts.push_back(p - Eigen::Vector2d(0, off));
          pts.push_back(p + Eigen::Vector2d(-off, off));
        }
      }
    }
  }
  return pts;
}

void ExpectZoneAtMatchesBruteForce(const WarehouseMap& map, const TrafficPredictor& pred,
                                   int n_random, int per_edge, std::uint32_t seed) {
  std::mt19937 rng(seed);
  const std::vector<Eigen::Vector2d> pts =
      ProbePoints(map, n_random, per_edge, 1.5, pred.zone_cell_size(), rng);
  int mismatches = 0;
  for (const Eigen::Vector2d& p : pts) {
    const ZoneId want = BruteForceZone(map, p);
    const ZoneId got = pred.ZoneAt(p);
    if (got != want && ++mismatches <= 10) {
      ADD_FAILURE() << "ZoneAt(" << p.x() << ", " << p.y() << ") = " << got << ", want " << want;
    }
  }
  EXPECT_EQ(mismatches, 0) << "of " << pts.size() << " points";
}

// --- ZoneAt -----------------------------------------------------------------------------------

TEST(TrafficPredictionZoneAtTest, MatchesBruteForceOnChu2024Floor) {
  const WarehouseMap map = BuildChu2024Floor().value();
  ASSERT_EQ(map.zones().size(), 6u);
  for (double cell : {0.25, 0.1, 1.0, 3.3}) {
    TrafficPredictionConfig config;
    config.zone_cell_size = cell;
    const TrafficPredictor pred(map, config);
    EXPECT_DOUBLE_EQ(pred.zone_cell_size(), cell);
    ExpectZoneAtMatchesBruteForce(map, pred, 50000, 20, 7);
  }
  const TrafficPredictor pred(map, {});
  EXPECT_EQ(pred.ZoneAt({1e9, 0}), -1);
  EXPECT_EQ(pred.ZoneAt({std::nan(""), 3.0}), -1);
  EXPECT_EQ(pred.ZoneAt({-1e9, -1e9}), -1);
  // Shared border x = 12.25 of Z1 | Z2: the lower id answers, as BruteForceZone does.
  EXPECT_EQ(pred.ZoneAt({12.25, 5.0}), map.FindZone("Z1").value());
  EXPECT_EQ(pred.ZoneAt({12.2500001, 5.0}), map.FindZone("Z2").value());
}

// A concave polygon with slanted edges, a triangle, a quad overlapping both and a rectangle
// inside the quad (interior overlaps: the lowest id wins).
WarehouseMap PolygonMap(bool overlapping) {
  MapBuilder b("polygons");
  b.SetFloor({0, 0}, {20, 10});
  b.AddZone("L", {{0, 0}, {12, 0}, {12, 3}, {5.3, 3.7}, {3.1, 10}, {0, 10}});
  b.AddZone("tri", {{12, 0}, {20, 0}, {20, 10}});
  if (overlapping) {
    b.AddZone("quad", {{4, 2}, {13, 2.5}, {19.7, 9.9}, {2.9, 9.5}});
    b.AddRectZone("rect", {8, 5}, {10, 7});
  } else {
    b.AddZone("quad", {{5.3, 3.7}, {12, 3}, {12, 0}, {20, 10}, {3.1, 10}});
  }
  b.AddPoint("a", {1, 1}, PointKind::kLane);
  b.AddPoint("b", {2, 1}, PointKind::kLane);
  b.AddPath("a", "b", std::nullopt, 0.0, true);
  return b.Build().value();
}

TEST(TrafficPredictionZoneAtTest, MatchesBruteForceOnNonRectangularZones) {
  for (bool overlapping : {false, true}) {
    const WarehouseMap map = PolygonMap(overlapping);
    for (double cell : {0.25, 0.07, 1.3}) {
      TrafficPredictionConfig config;
      config.zone_cell_size = cell;
      const TrafficPredictor pred(map, config);
      ExpectZoneAtMatchesBruteForce(map, pred, 50000, 20, 11);
    }
  }
}

// A zone border a hair (2e-10 m) past a cell border: Zone::Contains of the lower-id zone
// accepts points just across it, inside a cell that lies wholly in the other zone. The grid
// must not answer that cell directly.
TEST(TrafficPredictionZoneAtTest, HairlineGapBetweenZoneBorderAndCellBorder) {
  const double cut = 5.0 + 2e-10;
  MapBuilder b("hairline");
  b.SetFloor({0, 0}, {10, 10});
  b.AddRectZone("right", {cut, 0}, {10, 10});  // id 0: wins on the shared border
  b.AddRectZone("left", {0, 0}, {cut, 10});
  b.AddPoint("a", {1, 1}, PointKind::kLane);
  b.AddPoint("b", {2, 1}, PointKind::kLane);
  b.AddPath("a", "b", std::nullopt, 0.0, true);
  const WarehouseMap map = b.Build().value();
  TrafficPredictionConfig config;
  config.zone_cell_size = 0.25;  // a cell border at x = 5
  const TrafficPredictor pred(map, config);
  for (int k = -2000; k <= 2000; ++k) {
    const Eigen::Vector2d p(5.0 + k * 1e-12, 3.3);
    EXPECT_EQ(pred.ZoneAt(p), BruteForceZone(map, p)) << "x = 5 + " << k << "e-12";
  }
}

// The LoRR warehouse_large scale: a 500 x 140 m floor cut into 700 zones of 10 x 10 m.
TEST(TrafficPredictionZoneAtTest, LorrScaleFloorIsFastAndExact) {
  MapBuilder b("lorr-like");
  b.SetFloor({0, 0}, {500, 140});
  for (int r = 0; r < 14; ++r) {
    for (int c = 0; c < 50; ++c) {
      b.AddRectZone("z" + std::to_string(r * 50 + c), {10.0 * c, 10.0 * r},
                    {10.0 * (c + 1), 10.0 * (r + 1)});
    }
  }
  b.AddPoint("a", {1, 1}, PointKind::kLane);
  b.AddPoint("b", {2, 1}, PointKind::kLane);
  b.AddPath("a", "b", std::nullopt, 0.0, true);
  const WarehouseMap map = b.Build().value();
  ASSERT_EQ(map.zones().size(), 700u);

  const auto t0 = std::chrono::steady_clock::now();
  const TrafficPredictor pred(map, {});
  const double build_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  std::printf("700-zone 500x140 m grid: cell %.3f m, built in %.1f ms\n", pred.zone_cell_size(),
              build_ms);
  EXPECT_DOUBLE_EQ(pred.zone_cell_size(), 0.25);
  ExpectZoneAtMatchesBruteForce(map, pred, 20000, 1, 13);
  EXPECT_EQ(pred.ZoneAt({10.0, 10.0}), 0);  // corner of z0, z1, z50, z51: the lowest id
  EXPECT_EQ(pred.ZoneAt({15.0, 135.0}), 13 * 50 + 1);
}

TEST(TrafficPredictionZoneAtTest, CellSizeGrowsToKeepTheGridBounded) {
  MapBuilder b("huge");
  b.SetFloor({0, 0}, {4000, 3000});
  b.AddZone("diamond", {{2000, 0}, {4000, 1500}, {2000, 3000}, {0, 1500}});
  b.AddPoint("a", {2000, 1500}, PointKind::kLane);
  b.AddPoint("b", {2001, 1500}, PointKind::kLane);
  b.AddPath("a", "b", std::nullopt, 0.0, true);
  const WarehouseMap map = b.Build().value();
  const TrafficPredictor pred(map, {});
  const double cell = pred.zone_cell_size();
  EXPECT_GT(cell, 0.25);
  const double cells = (std::floor(4000 / cell) + 3) * (std::floor(3000 / cell) + 3);
  EXPECT_LE(cells, static_cast<double>(TrafficPredictionConfig::kMaxZoneCells));
  ExpectZoneAtMatchesBruteForce(map, pred, 20000, 20, 17);
}

}  // namespace
}  // namespace dispatch::engine
