// PointGrid answers nearest-point queries exactly as a scan in id order would: the nearest
// point, the lowest id among equally near ones, on random point sets (clustered, on a line,
// with duplicates) and for queries anywhere in the bounding box, on points and on cell edges;
// with a hint (NearestFrom) the same answers.
#include "engine/map/point_grid.h"

#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "engine/map/chu2024_floor.h"
#include "engine/map/grid_floor.h"
#include "engine/map/warehouse_map.h"

namespace dispatch::engine {
namespace {

std::pair<PointId, double> Scan(const std::vector<Point>& points, const Eigen::Vector2d& xy) {
  double best = std::numeric_limits<double>::infinity();
  PointId id = kNoPoint;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double d = (points[i].position - xy).norm();
    if (d < best) best = d, id = static_cast<PointId>(i);
  }
  return {id, best};
}

std::vector<Point> RandomPoints(std::mt19937& rng, int n, int shape) {
  std::uniform_real_distribution<double> u(-50.0, 150.0);
  std::vector<Point> points(static_cast<std::size_t>(n));
  for (auto& p : points) {
    switch (shape) {
      case 0: p.position = {u(rng), u(rng)}; break;                            // scattered
      case 1: p.position = {std::round(u(rng)), std::round(u(rng) / 10)}; break;  // grid rows, duplicates
      case 2: p.position = {u(rng), 3.0}; break;                               // on a line
      default: p.position = {u(rng) / 100, u(rng) / 100}; break;               // one tight cluster
    }
  }
  return points;
}

TEST(PointGridTest, AgreesWithAScanInIdOrder) {
  std::mt19937 rng(7);
  for (int shape = 0; shape < 4; ++shape) {
    for (int n : {1, 2, 17, 500}) {
      const std::vector<Point> points = RandomPoints(rng, n, shape);
      const PointGrid grid(points);
      Eigen::Vector2d lo = points[0].position, hi = lo;
      for (const auto& p : points) lo = lo.cwiseMin(p.position), hi = hi.cwiseMax(p.position);
      std::uniform_real_distribution<double> ux(lo.x(), hi.x()), uy(lo.y(), hi.y());
      for (int q = 0; q < 400; ++q) {
        Eigen::Vector2d xy = q % 4 == 0 ? points[rng() % points.size()].position : Eigen::Vector2d(ux(rng), uy(rng));
        PointId id = kNoPoint;
        double d = 0;
        ASSERT_TRUE(grid.Nearest(xy, &id, &d)) << "shape " << shape << " n " << n;
        const auto [want, want_d] = Scan(points, xy);
        ASSERT_EQ(id, want) << "shape " << shape << " n " << n << " at " << xy.transpose();
        ASSERT_EQ(d, want_d);
      }
    }
  }
}

TEST(PointGridTest, AHintGivesTheSameAnswerAsTheSearch) {
  // NearestFrom with any hint (the right point, a neighbour, a far one, none) answers as
  // Nearest: queries near points (a robot on its way) and anywhere in the box.
  std::mt19937 rng(11);
  for (int shape = 0; shape < 4; ++shape) {
    for (int n : {1, 2, 17, 500}) {
      const std::vector<Point> points = RandomPoints(rng, n, shape);
      const PointGrid grid(points);
      Eigen::Vector2d lo = points[0].position, hi = lo;
      for (const auto& p : points) lo = lo.cwiseMin(p.position), hi = hi.cwiseMax(p.position);
      std::uniform_real_distribution<double> ux(lo.x(), hi.x()), uy(lo.y(), hi.y()), jitter(-0.6, 0.6);
      for (int q = 0; q < 400; ++q) {
        const Eigen::Vector2d& near = points[rng() % points.size()].position;
        const Eigen::Vector2d xy = q % 2 == 0 ? Eigen::Vector2d(near + Eigen::Vector2d(jitter(rng), jitter(rng)))
                                              : Eigen::Vector2d(ux(rng), uy(rng));
        PointId want = kNoPoint, id = kNoPoint;
        double want_d = 0, d = 0;
        const bool answered = grid.Nearest(xy, &want, &want_d);
        PointId hints[] = {want, static_cast<PointId>(rng() % points.size()), kNoPoint, static_cast<PointId>(n + 3)};
        for (PointId hint : hints) {
          const bool got = grid.NearestFrom(xy, hint, &id, &d);
          if (!answered && got) {  // outside the box the hint may answer; then it is the scan's
            ASSERT_EQ(id, Scan(points, xy).first) << "shape " << shape << " n " << n;
            continue;
          }
          ASSERT_EQ(got, answered);
          if (!got) continue;
          ASSERT_EQ(id, want) << "shape " << shape << " n " << n << " hint " << hint << " at " << xy.transpose();
          ASSERT_DOUBLE_EQ(d, want_d);
        }
      }
    }
  }
}

TEST(PointGridTest, TheMapsHintedLookupAnswersAsTheSearchAlongEveryArc) {
  // WarehouseMap::NearestPointFrom tries the hint and the points one arc from it: a robot on
  // any arc, hinted with either end, a point two arcs away or a far one, gets NearestPoint's
  // answer (the Chu2024 floor: uneven gaps, docks off the lanes; a grid floor: ties midway).
  GridFloorOptions small;
  small.shelf_cols = 3;
  small.shelf_rows = 3;
  for (auto built : {BuildChu2024Floor(), BuildGridFloor(small)}) {
    ASSERT_TRUE(built.ok()) << built.error().message;
    const WarehouseMap& map = *built;
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> along(0.0, 1.0), jitter(-0.05, 0.05);
    for (const Arc& a : map.arcs()) {
      const Eigen::Vector2d from = map.point(a.from).position, to = map.point(a.to).position;
      const PointId beyond = map.out_arcs(a.to).empty() ? a.to : map.arc(map.out_arcs(a.to).front()).to;
      for (double f : {0.0, 0.25, 0.5, 0.75, 1.0, along(rng)}) {
        const Eigen::Vector2d xy = from + f * (to - from) + Eigen::Vector2d(jitter(rng), jitter(rng));
        const PointId want = map.NearestPoint(xy);
        for (PointId hint : {a.from, a.to, beyond, static_cast<PointId>(rng() % map.point_count()), kNoPoint}) {
          ASSERT_EQ(map.NearestPointFrom(xy, hint), want) << "arc " << map.point(a.from).name << " -> "
                                                          << map.point(a.to).name << " at " << f << " hint " << hint;
        }
      }
    }
  }
}

TEST(PointGridTest, DeclinesWhatItCannotAnswer) {
  std::vector<Point> points(3);
  points[0].position = {0, 0};
  points[1].position = {10, 0};
  points[2].position = {10, 10};
  const PointGrid grid(points);
  PointId id = kNoPoint;
  double d = 0;
  EXPECT_FALSE(grid.Nearest({-1, 5}, &id, &d));  // outside the bounding box
  EXPECT_FALSE(grid.Nearest({std::nan(""), 5}, &id, &d));
  EXPECT_FALSE(PointGrid().Nearest({0, 0}, &id, &d));
  ASSERT_TRUE(grid.Nearest({9, 9}, &id, &d));
  EXPECT_EQ(id, 2);
}

}  // namespace
}  // namespace dispatch::engine
