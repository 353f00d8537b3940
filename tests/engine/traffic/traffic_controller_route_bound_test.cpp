// TrafficController::SetRouteBound: bounded detour searches that skip points which cannot
// arrive in time must take exactly the decisions the plain searches take. Two controllers,
// one with the bound and one without, drive the same fleet through the same random goals on a
// warehouse floor (aisles, racks, intersections) and must agree on every robot after every
// step; the run must have detoured (else the bound was never used).
#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <stdexcept>
#include <vector>

#include "engine/map/grid_floor.h"
#include "engine/routing/route_table.h"
#include "engine/traffic/traffic_controller.h"

namespace dispatch::engine {
namespace {

struct Floor {
  std::shared_ptr<const WarehouseMap> map;
  std::shared_ptr<const RouteTable> routes;
};

Floor SmallFloor(double turn_penalty = 0.0, RouteTableMethod method = RouteTableMethod::kFloyd) {
  GridFloorOptions o;
  o.shelf_rows = 4;
  o.shelf_cols = 4;
  auto m = BuildGridFloor(o);
  if (!m.ok()) throw std::runtime_error(m.error().message);
  Floor f;
  f.map = std::make_shared<const WarehouseMap>(std::move(m).value());
  RouteTableOptions ro;
  ro.turn_penalty_s = turn_penalty;
  ro.method = method;
  auto t = MakeRouteTable(f.map, ro);
  if (!t.ok()) throw std::runtime_error(t.error().message);
  f.routes = std::move(t).value();
  return f;
}

TrafficController Make(const Floor& f, bool bounded) {
  TrafficControllerConfig c;
  c.blocked_after = 1e9;  // nobody gives up: the run keeps detouring
  auto created = TrafficController::Create(f.map, c);
  if (!created.ok()) throw std::runtime_error(created.error().message);
  TrafficController ctl = std::move(created).value();
  if (bounded) ctl.SetRouteBound(f.routes);
  return ctl;
}

// Drives both controllers with the same fleet and goals; returns the detours taken.
std::size_t DriveSideBySide(const Floor& f, unsigned seed) {
  TrafficController plain = Make(f, false);
  TrafficController bounded = Make(f, true);
  std::mt19937 rng(seed);
  const auto n = static_cast<PointId>(f.map->point_count());
  std::uniform_int_distribution<PointId> any(0, n - 1);
  constexpr std::size_t kRobots = 24;
  for (std::size_t i = 0; i < kRobots; ++i) {
    for (;;) {
      const PointId p = any(rng);
      auto a = plain.AddRobot("R" + std::to_string(i), p);
      if (!a.ok()) continue;  // taken
      EXPECT_TRUE(bounded.AddRobot("R" + std::to_string(i), p).ok());
      break;
    }
  }
  for (int step = 0; step < 400; ++step) {
    const double t = step * 1.0;
    for (std::size_t r = 0; r < kRobots; ++r) {
      if (plain.Next(r) == kNoPoint && !plain.HasRoute(r)) {  // at its goal: a new one
        auto path = f.routes->Path(plain.At(r), any(rng));
        if (!path.ok() || path->points.size() < 2) continue;
        EXPECT_TRUE(plain.SetRoute(r, path->points).ok());
        EXPECT_TRUE(bounded.SetRoute(r, path->points).ok());
      }
    }
    for (TrafficController* ctl : {&plain, &bounded}) {
      for (std::size_t r = 0; r < kRobots; ++r) {
        if (ctl->Next(r) != kNoPoint) {
          ctl->Arrived(r, t);
        } else if (ctl->HasRoute(r)) {
          while (ctl->Request(r, t) == TrafficDecision::kReplanned) {
          }
        }
      }
      ctl->ResolveDeadlocks(t);
    }
    for (std::size_t r = 0; r < kRobots; ++r) {
      EXPECT_EQ(plain.At(r), bounded.At(r)) << "robot " << r << " step " << step;
      EXPECT_EQ(plain.Next(r), bounded.Next(r)) << "robot " << r << " step " << step;
      if (plain.RemainingRoute(r) != bounded.RemainingRoute(r)) {
        ADD_FAILURE() << "robot " << r << " routes differ at step " << step;
        return 0;
      }
    }
  }
  EXPECT_EQ(plain.stats().head_on_conflicts, bounded.stats().head_on_conflicts);
  EXPECT_EQ(plain.stats().deadlocks_resolved, bounded.stats().deadlocks_resolved);
  EXPECT_EQ(plain.stats().nudges, bounded.stats().nudges);
  EXPECT_EQ(plain.stats().replans, bounded.stats().replans);
  return bounded.stats().replans;
}

// A dense table (Cost per query) and a lazy one (costs read in place, RouteTable::CostsTo).
TEST(TrafficControllerRouteBoundTest, BoundedSearchesTakeTheSameDecisions) {
  for (RouteTableMethod method : {RouteTableMethod::kFloyd, RouteTableMethod::kLazy}) {
    SCOPED_TRACE(method == RouteTableMethod::kLazy ? "lazy" : "floyd");
    const Floor f = SmallFloor(0.0, method);
    ASSERT_EQ(f.routes->CostsTo(0) != nullptr, method == RouteTableMethod::kLazy);
    std::size_t replans = 0;
    for (unsigned seed : {1u, 2u, 3u}) {
      SCOPED_TRACE(seed);
      replans += DriveSideBySide(f, seed);
    }
    EXPECT_GT(replans, 20u) << "too few detours to exercise the bound";
  }
}

// A table with turn penalties costs more than the controller's arc times: it is no lower
// bound and is ignored (the decisions stay those of the plain searches).
TEST(TrafficControllerRouteBoundTest, ATableWithTurnPenaltiesIsIgnored) {
  const Floor f = SmallFloor(5.0);
  EXPECT_GT(DriveSideBySide(f, 4u), 0u);
}

}  // namespace
}  // namespace dispatch::engine
