#include "engine/planning/window_planner.h"

#include <gtest/gtest.h>

#include <random>

#include "engine/map/grid_floor.h"
#include "grid_map.h"

namespace dispatch::engine {
namespace {

using testing_grid::At;
using testing_grid::GridMap;
using testing_grid::Routes;

WindowRequest Request(int robot, PointId start, double t, std::vector<WindowStop> stops, double release = 0.0) {
  WindowRequest r;
  r.robot = robot;
  r.start = start;
  r.start_time = t;
  r.stops = std::move(stops);
  r.release_time = release;
  return r;
}

TEST(WindowPlannerTest, AloneARobotDrivesItsShortestRouteAtCruiseSpeed) {
  const auto map = GridMap({".....", ".@@@.", "....."});
  const auto routes = Routes(map);
  ReservationTable table(map, {});
  const auto plan = PlanInWindows(table, *routes, Request(0, At(*map, 0, 0), 10.0, {{At(*map, 2, 4), 0.0}}));
  ASSERT_TRUE(plan.ok()) << plan.error().message;
  const TimedRoute& route = plan.value().route;
  EXPECT_EQ(route.front().point, At(*map, 0, 0));
  EXPECT_EQ(route.back().point, At(*map, 2, 4));
  EXPECT_DOUBLE_EQ(route.back().arrive, 16.0);  // 6 m at 1 m/s from t = 10
  EXPECT_TRUE(std::isinf(route.back().depart));  // it stays
  EXPECT_EQ(route.size(), 7u);
  EXPECT_TRUE(CheckTimeWindows(*map, {}, {route}).ok());
}

TEST(WindowPlannerTest, ARobotWorksAtEachStopForItsWorkTime) {
  const auto map = GridMap({"....."});
  const auto routes = Routes(map);
  ReservationTable table(map, {});
  const auto plan = PlanInWindows(table, *routes,
                                  Request(0, At(*map, 0, 0), 0.0, {{At(*map, 0, 2), 5.0}, {At(*map, 0, 4), 3.0}}));
  ASSERT_TRUE(plan.ok()) << plan.error().message;
  const TimedRoute& route = plan.value().route;
  ASSERT_EQ(route.size(), 5u);
  EXPECT_DOUBLE_EQ(route[2].arrive, 2.0);
  EXPECT_DOUBLE_EQ(route[2].depart, 7.0);  // worked 5 s at the pick
  EXPECT_DOUBLE_EQ(route[4].arrive, 9.0);
  EXPECT_TRUE(std::isinf(route[4].depart));
}

TEST(WindowPlannerTest, TurningTimeDelaysTheArrival) {
  const auto map = GridMap({"..", "@."});
  const auto routes = Routes(map);
  TimeWindowRules rules;
  rules.turn_s_per_90 = 1.5;
  ReservationTable table(map, rules);
  const auto plan = PlanInWindows(table, *routes, Request(0, At(*map, 0, 0), 0.0, {{At(*map, 1, 1), 0.0}}));
  ASSERT_TRUE(plan.ok());
  EXPECT_DOUBLE_EQ(plan.value().route.back().arrive, 3.5);  // 2 m and one right angle
}

// Wang2019 §2.3: a lane is driven one way at a time. The second robot, in the siding above a
// corridor the first drives along, waits there until the first has passed and cleared.
TEST(WindowPlannerTest, ASecondRobotGivesWayInTheFreeWindowsTheFirstLeaves) {
  const auto map = GridMap({"@@.@@", "....."});
  const auto routes = Routes(map);
  ReservationTable table(map, {});
  const auto first = PlanInWindows(table, *routes, Request(0, At(*map, 1, 0), 0.0, {{At(*map, 1, 4), 0.0}}));
  ASSERT_TRUE(first.ok()) << first.error().message;
  EXPECT_DOUBLE_EQ(first.value().route.back().arrive, 4.0);
  ASSERT_TRUE(table.Reserve(0, first.value().route).ok());
  const auto second = PlanInWindows(table, *routes, Request(1, At(*map, 0, 2), 0.0, {{At(*map, 1, 0), 0.0}}));
  ASSERT_TRUE(second.ok()) << second.error().message;
  EXPECT_TRUE(CheckTimeWindows(*map, {}, {first.value().route, second.value().route}).ok());
  // Alone it would arrive at 2 s; the first holds r1c2 until 3 s (left at 2, clear 1 s) and
  // the lane r1c1-r1c2 eastwards until 2 s: it leaves the siding at 2 and arrives at 5.
  EXPECT_DOUBLE_EQ(second.value().route.front().depart, 2.0);
  EXPECT_DOUBLE_EQ(second.value().route.back().arrive, 5.0);
}

TEST(WindowPlannerTest, AStartHeldByAnotherOrAGoalNeverFreeIsUnreachable) {
  const auto map = GridMap({"...."});
  const auto routes = Routes(map);
  ReservationTable table(map, {});
  ASSERT_TRUE(table.Reserve(5, {{At(*map, 0, 3), 0.0, kForever}}).ok());
  const auto held = PlanInWindows(table, *routes, Request(0, At(*map, 0, 3), 1.0, {}));
  ASSERT_FALSE(held.ok());
  EXPECT_EQ(held.error().code, ErrorCode::kUnreachable);
  EXPECT_NE(held.error().message.find("held by another robot"), std::string::npos);
  const auto never = PlanInWindows(table, *routes, Request(0, At(*map, 0, 0), 0.0, {{At(*map, 0, 3), 0.0}}));
  EXPECT_EQ(never.error().code, ErrorCode::kUnreachable);
  EXPECT_EQ(PlanInWindows(table, *routes, Request(0, 42, 0.0, {})).error().code, ErrorCode::kInvalidArgument);
  EXPECT_EQ(PlanInWindows(table, *routes, Request(0, At(*map, 0, 0), 0.0, {{At(*map, 0, 1), -1.0}})).error().code,
            ErrorCode::kInvalidArgument);
}

TEST(WindowPlannerTest, RobotsArePlannedWorkingFirstThenByReleaseTime) {
  const auto map = GridMap({"....."});
  const auto routes = Routes(map);
  ReservationTable table(map, {});
  std::vector<WindowRequest> requests = {
      Request(0, At(*map, 0, 0), 0.0, {{At(*map, 0, 1), 0.0}}, 30.0),
      Request(1, At(*map, 0, 4), 0.0, {{At(*map, 0, 3), 0.0}}, 10.0),
      Request(2, At(*map, 0, 2), 0.0, {{At(*map, 0, 2), 0.0}}, 20.0),
  };
  requests[0].working = true;
  const auto plans = PlanInPriorityOrder(table, *routes, requests);
  ASSERT_TRUE(plans.ok());
  EXPECT_EQ(plans.value().order, (std::vector<std::size_t>{0, 1, 2}));
  requests[0].working = false;
  ReservationTable again(map, {});
  EXPECT_EQ(PlanInPriorityOrder(again, *routes, requests).value().order, (std::vector<std::size_t>{1, 2, 0}));
}

// Model test: robots with random starts and two random stops on a grid floor, planned in
// priority order, hold windows no two of which conflict (the one checker); each route starts
// where its robot stands and visits its stops in order.
TEST(WindowPlannerTest, RandomFleetsOnAGridFloorAreConflictFree) {
  GridFloorOptions options;
  options.shelf_rows = 3;
  options.shelf_cols = 3;
  auto built = BuildGridFloor(options);
  ASSERT_TRUE(built.ok());
  const auto map = std::make_shared<const WarehouseMap>(std::move(built).value());
  const auto routes = Routes(map);
  std::mt19937_64 random(42);
  int planned = 0, asked = 0;
  for (int round = 0; round < 8; ++round) {
    std::vector<PointId> cells(map->point_count());
    for (std::size_t i = 0; i < cells.size(); ++i) cells[i] = static_cast<PointId>(i);
    std::shuffle(cells.begin(), cells.end(), random);
    std::vector<WindowRequest> requests;
    const int n = 10 + round * 3;
    for (int i = 0; i < n; ++i) {  // starts and last stops distinct: where they stay
      const PointId pick = cells[static_cast<std::size_t>(2 * n + static_cast<int>(random() % static_cast<unsigned>(n)))];
      requests.push_back(Request(i, cells[static_cast<std::size_t>(i)], 0.0,
                                 {{pick, 2.0}, {cells[static_cast<std::size_t>(n + i)], 1.0}},
                                 static_cast<double>(random() % 100)));
    }
    ReservationTable table(map, {});
    const auto plans = PlanInPriorityOrder(table, *routes, requests);
    ASSERT_TRUE(plans.ok());
    std::vector<TimedRoute> done;
    for (std::size_t i = 0; i < requests.size(); ++i) {
      ++asked;
      const TimedRoute& r = plans.value().routes[i];
      if (r.empty()) continue;
      ++planned;
      EXPECT_EQ(r.front().point, requests[i].start);
      std::size_t next = 0;
      for (const TimedVisit& v : r) {
        if (next < requests[i].stops.size() && v.point == requests[i].stops[next].point &&
            v.depart - v.arrive >= requests[i].stops[next].work_s - 1e-9) {
          ++next;
        }
      }
      EXPECT_EQ(next, requests[i].stops.size()) << "robot " << i;
      done.push_back(r);
    }
    const Status check = CheckTimeWindows(*map, {}, done);
    EXPECT_TRUE(check.ok()) << "round " << round << ": " << check.error().message;
  }
  EXPECT_GE(planned * 10, asked * 9);  // nearly every robot finds a route
  RecordProperty("planned", planned);
  RecordProperty("asked", asked);
}

// The route table with every cost 0 where reachable: the search without its heuristic
// (Dijkstra order), to hold the A* to.
class NoHeuristic : public RouteTable {
 public:
  explicit NoHeuristic(const RouteTable& t) : t_(t) {}
  std::size_t point_count() const override { return t_.point_count(); }
  double Cost(PointId a, PointId b) const override { return std::isinf(t_.Cost(a, b)) ? kForever : 0.0; }
  PointId NextHop(PointId a, PointId b) const override { return t_.NextHop(a, b); }
  Result<Route> Path(PointId a, PointId b) const override { return t_.Path(a, b); }
  std::string_view method() const override { return "none"; }

 private:
  const RouteTable& t_;
};

// Model test: into a busy table, the heuristic search and the blind one reach every stop at
// the same times (the heuristic and the goal's free-interval bound are admissible).
TEST(WindowPlannerTest, TheHeuristicSearchArrivesAsEarlyAsTheBlindOne) {
  GridFloorOptions options;
  options.shelf_rows = 3;
  options.shelf_cols = 4;
  const auto map = std::make_shared<const WarehouseMap>(BuildGridFloor(options).value());
  const auto routes = Routes(map);
  const NoHeuristic blind(*routes);
  std::mt19937_64 random(5);
  std::vector<PointId> cells(map->point_count());
  for (std::size_t i = 0; i < cells.size(); ++i) cells[i] = static_cast<PointId>(i);
  std::shuffle(cells.begin(), cells.end(), random);
  const std::size_t n = 40, extra = 20;
  std::vector<WindowRequest> requests;
  for (std::size_t i = 0; i < n + extra; ++i) {
    requests.push_back(Request(static_cast<int>(i), cells[i], 0.0,
                               {{cells[2 * (n + extra) + random() % 50], 1.0}, {cells[n + extra + i], 0.0}},
                               static_cast<double>(random() % 30)));
  }
  ReservationTable table(map, {});
  ASSERT_TRUE(PlanInPriorityOrder(table, *routes, {requests.begin(), requests.begin() + n}).ok());
  int compared = 0;
  for (std::size_t i = n; i < n + extra; ++i) {
    const auto fast = PlanInWindows(table, *routes, requests[i]);
    const auto slow = PlanInWindows(table, blind, requests[i]);
    ASSERT_EQ(fast.ok(), slow.ok()) << i;
    if (!fast.ok()) continue;
    ++compared;
    auto arrival_at = [](const TimedRoute& r, PointId p) {
      for (const TimedVisit& v : r) {
        if (v.point == p && v.depart - v.arrive >= 1.0 - 1e-9) return v.arrive;  // worked there
      }
      return r.back().arrive;
    };
    EXPECT_DOUBLE_EQ(arrival_at(fast.value().route, requests[i].stops[0].point),
                     arrival_at(slow.value().route, requests[i].stops[0].point));
    EXPECT_DOUBLE_EQ(fast.value().route.back().arrive, slow.value().route.back().arrive) << i;
    EXPECT_LE(fast.value().expanded, slow.value().expanded);
    EXPECT_TRUE(CheckTimeWindows(*map, {}, {*table.RouteOf(0), fast.value().route}).ok());
  }
  EXPECT_GE(compared, 15);
}

TEST(WindowPlannerTest, TheLimitsStopTheSearch) {
  const auto map = GridMap({"..........", "..........", ".........."});
  const auto routes = Routes(map);
  ReservationTable table(map, {});
  PlanLimits few;
  few.max_expansions = 2;
  const auto stopped = PlanInWindows(table, *routes, Request(0, At(*map, 0, 0), 0.0, {{At(*map, 2, 9), 0.0}}), few);
  ASSERT_FALSE(stopped.ok());
  EXPECT_EQ(stopped.error().code, ErrorCode::kFailedPrecondition);
}

}  // namespace
}  // namespace dispatch::engine
