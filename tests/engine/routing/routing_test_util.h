// Shared fixtures for the routing tests: seeded random cost graphs and maps, and the checkers
// every implementation is held to (a path is consecutive existing arcs from -> to whose summed
// cost equals the reported cost).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <queue>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "engine/map/map_builder.h"
#include "engine/routing/cost_graph.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine::testing {

inline constexpr double kInf = std::numeric_limits<double>::infinity();

// Dense answers are float: allow a small relative error against double Dijkstra.
inline bool CostsAgree(double expected, double actual) {
  if (std::isinf(expected) || std::isinf(actual)) return expected == actual;
  return std::abs(expected - actual) <= 1e-5 * std::max(1.0, std::abs(expected));
}

// Random digraph with unreachable pairs (an isolated tail of vertices, one-way arcs), zero-cost
// arcs, parallel arcs and self-loops.
inline CostGraph RandomCostGraph(unsigned seed, int n, double arcs_per_vertex) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> pick(0, std::max(0, n - 1));
  std::uniform_real_distribution<double> cost(0.0, 10.0);
  std::vector<CostArc> arcs;
  const int connected = std::max(1, n - n / 8);  // the last n/8 vertices only get out-arcs
  const auto m = static_cast<int>(arcs_per_vertex * n);
  for (int i = 0; i < m && n > 0; ++i) {
    const int from = pick(rng);
    const int to = pick(rng) % connected;
    const int kind = static_cast<int>(rng() % 10);
    const double c = kind == 0 ? 0.0 : cost(rng);
    arcs.push_back({from, to, c});
    if (kind == 1) arcs.push_back({from, to, c * 0.5 + 1.0});  // parallel, dearer or cheaper
  }
  return CostGraph::Build(static_cast<std::size_t>(n), std::move(arcs)).value();
}

// Random map: points on a jittered grid, random one-way and bidirectional lanes (some curved,
// some slow), a few isolated points. All points are lanes, so Build's connectivity check holds.
inline std::shared_ptr<const WarehouseMap> RandomMap(unsigned seed, int side) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3), unit(0.0, 1.0);
  MapBuilder b("random" + std::to_string(seed));
  b.AddRectZone("floor", {-1.0, -1.0}, {side * 2.0 + 1.0, side * 2.0 + 1.0});
  auto name = [](int x, int y) { return "p" + std::to_string(x) + "_" + std::to_string(y); };
  for (int y = 0; y < side; ++y) {
    for (int x = 0; x < side; ++x) {
      b.AddPoint(name(x, y), {x * 2.0 + jitter(rng), y * 2.0 + jitter(rng)}, PointKind::kLane);
    }
  }
  for (int y = 0; y < side; ++y) {
    for (int x = 0; x < side; ++x) {
      const int nbr[3][2] = {{1, 0}, {0, 1}, {1, 1}};
      for (const auto& d : nbr) {
        const int nx = x + d[0], ny = y + d[1];
        if (nx >= side || ny >= side || unit(rng) < (d[0] && d[1] ? 0.8 : 0.2)) continue;
        const bool forward = unit(rng) < 0.5;
        const std::string a = forward ? name(x, y) : name(nx, ny);
        const std::string c = forward ? name(nx, ny) : name(x, y);
        const double r = unit(rng);
        const std::optional<double> length =
            r < 0.2 ? std::optional<double>(3.5 + unit(rng) * 2.0) : std::nullopt;
        const double max_speed = r > 0.8 ? 0.5 : 0.0;
        b.AddPath(a, c, length, max_speed, unit(rng) < 0.6);
      }
    }
  }
  return std::make_shared<const WarehouseMap>(b.Build().value());
}

// Independent reference: per-source Dijkstra over (point, arrival arc) states, written without
// the library's cost graph. Cost of an arc = length / min(speed, max_speed), times its
// weight when `weight` (one per map arc) is given; turns cost penalty * angle / 90 degrees.
inline std::vector<double> ReferenceCosts(const WarehouseMap& map, PointId source, double speed,
                                          double penalty, const std::vector<double>* weight = nullptr) {
  const std::size_t p = map.point_count();
  auto arc_cost = [&](ArcId a) {
    const Arc& arc = map.arc(a);
    const double w = weight ? (*weight)[static_cast<std::size_t>(a)] : 1.0;
    return w * arc.length / (arc.max_speed > 0 ? std::min(speed, arc.max_speed) : speed);
  };
  auto heading = [&](ArcId a) {
    const Arc& arc = map.arc(a);
    const Eigen::Vector2d d = map.point(arc.to).position - map.point(arc.from).position;
    return std::atan2(d.y(), d.x());
  };
  auto turn = [&](ArcId a, ArcId b) {
    double t = std::abs(heading(b) - heading(a));
    if (t > std::numbers::pi) t = 2 * std::numbers::pi - t;
    return penalty * t / (std::numbers::pi / 2);
  };
  // State: 0 = at source without heading, 1 + a = arrived via arc a.
  std::vector<double> dist(map.arcs().size() + 1, kInf);
  using Item = std::pair<double, std::size_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> heap;
  dist[0] = 0;
  heap.emplace(0.0, 0);
  while (!heap.empty()) {
    auto [d, s] = heap.top();
    heap.pop();
    if (d > dist[s]) continue;
    const PointId at = s == 0 ? source : map.arc(static_cast<ArcId>(s - 1)).to;
    for (ArcId b : map.out_arcs(at)) {
      const double nd = d + arc_cost(b) + (s == 0 ? 0.0 : turn(static_cast<ArcId>(s - 1), b));
      if (nd < dist[static_cast<std::size_t>(b) + 1]) {
        dist[static_cast<std::size_t>(b) + 1] = nd;
        heap.emplace(nd, static_cast<std::size_t>(b) + 1);
      }
    }
  }
  std::vector<double> out(p, kInf);
  out[static_cast<std::size_t>(source)] = 0;
  for (std::size_t a = 0; a < map.arcs().size(); ++a) {
    auto& o = out[static_cast<std::size_t>(map.arcs()[a].to)];
    o = std::min(o, dist[a + 1]);
  }
  return out;
}

// Checks Path(from, to) against Cost and the map: consecutive existing arcs, right ends,
// summed cost (recomputed here, turns included) and length.
inline void ExpectValidRoute(const WarehouseMap& map, const RouteTable& table, PointId from,
                             PointId to, double speed, double penalty) {
  const double cost = table.Cost(from, to);
  Result<Route> route = table.Path(from, to);
  if (std::isinf(cost)) {
    ASSERT_FALSE(route.ok()) << from << " -> " << to;
    EXPECT_EQ(route.error().code, ErrorCode::kUnreachable);
    EXPECT_EQ(table.NextHop(from, to), kNoPoint);
    return;
  }
  ASSERT_TRUE(route.ok()) << route.error().message;
  const Route& r = route.value();
  ASSERT_EQ(r.points.size(), r.arcs.size() + 1);
  ASSERT_EQ(r.points.front(), from);
  ASSERT_EQ(r.points.back(), to);
  double sum = 0, length = 0;
  for (std::size_t i = 0; i < r.arcs.size(); ++i) {
    ASSERT_GE(r.arcs[i], 0);
    ASSERT_LT(static_cast<std::size_t>(r.arcs[i]), map.arcs().size());
    const Arc& a = map.arc(r.arcs[i]);
    ASSERT_EQ(a.from, r.points[i]);
    ASSERT_EQ(a.to, r.points[i + 1]);
    sum += a.length / (a.max_speed > 0 ? std::min(speed, a.max_speed) : speed);
    length += a.length;
    if (i > 0 && penalty > 0) {
      sum += penalty * TurnAngle(map, r.arcs[i - 1], r.arcs[i]) / (std::numbers::pi / 2);
    }
  }
  EXPECT_NEAR(r.cost, sum, 1e-9 * std::max(1.0, sum));
  EXPECT_NEAR(r.length, length, 1e-9 * std::max(1.0, length));
  EXPECT_TRUE(CostsAgree(cost, sum)) << from << " -> " << to << ": " << cost << " vs " << sum;
  EXPECT_EQ(table.NextHop(from, to), r.points.size() > 1 ? r.points[1] : kNoPoint);
}

// Every pair of `map`'s points: the reference's cost (exact to 1e-9), a NextHop exactly when a
// route exists, and a valid route of that cost (ExpectValidRoute). `also(u, v)` adds a check.
template <class Also = void (*)(PointId, PointId)>
void ExpectReferenceAnswers(const WarehouseMap& map, const RouteTable& table, double speed, double penalty,
                            Also also = [](PointId, PointId) {}) {
  const auto n = static_cast<PointId>(map.point_count());
  for (PointId u = 0; u < n; ++u) {
    const std::vector<double> ref = ReferenceCosts(map, u, speed, penalty);
    for (PointId v = 0; v < n; ++v) {
      const double expected = ref[static_cast<std::size_t>(v)];
      if (std::isinf(expected)) {
        ASSERT_TRUE(std::isinf(table.Cost(u, v))) << u << "->" << v;
      } else {
        ASSERT_NEAR(table.Cost(u, v), expected, 1e-9 * std::max(1.0, expected)) << u << "->" << v;
      }
      also(u, v);
      EXPECT_EQ(std::isinf(expected), table.NextHop(u, v) == kNoPoint && u != v);
      ExpectValidRoute(map, table, u, v, speed, penalty);
      if (::testing::Test::HasFatalFailure()) return;
    }
  }
}

}  // namespace dispatch::engine::testing
