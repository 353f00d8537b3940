#include "engine/fleet/plan.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "engine/map/chu2024_floor.h"
#include "engine/map/map_builder.h"

namespace dispatch::engine {
namespace {

class PlanTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    map_ = std::make_shared<const WarehouseMap>(BuildChu2024Floor().value());
    routes_ = std::shared_ptr<const RouteTable>(MakeRouteTable(map_, {}).value().release());
  }
  static PointId Pick(double x, double y) { return Nearest(x, y, PointKind::kPick); }
  static PointId Drop(double x, double y) { return Nearest(x, y, PointKind::kDrop); }
  static PointId Nearest(double x, double y, PointKind kind) {
    double d = 0;
    const PointId p = map_->NearestPoint({x, y}, kind, &d);
    EXPECT_LT(d, 1e-9);
    return p;
  }
  static std::shared_ptr<const WarehouseMap> map_;
  static std::shared_ptr<const RouteTable> routes_;
};
std::shared_ptr<const WarehouseMap> PlanTest::map_;
std::shared_ptr<const RouteTable> PlanTest::routes_;

// ETAs at every stop equal the cumulative Route.length / v plus t_w at every earlier task
// point; the plan ends after the last drop's work. Recomputed from the route table alone.
TEST_F(PlanTest, StopEtasAreRouteLengthOverSpeedPlusWorkTimes) {
  const PointId start = map_->FindPoint("park-P1").value();
  // Seed table 1, tasks 4 and 5, for one robot.
  const std::vector<PlanTask> tasks = {
      {{Pick(29, 13), Pick(30.5, 13), Pick(29, 10.5)}, Drop(32.25, 5), 5.0},
      {{Pick(10.5, 13), Pick(10.5, 9)}, Drop(11.5, 2.75), 3.0, 2.0}};
  const double v = 1.5, t0 = 100.0;
  const Result<Plan> plan = BuildPlan(*map_, *routes_, start, t0, v, tasks);
  ASSERT_TRUE(plan.ok()) << plan.error().message;
  const std::vector<Waypoint>& w = plan->waypoints;

  std::vector<std::pair<PointId, WaypointAction>> stops;
  for (const PlanTask& task : tasks) {
    for (PointId p : task.picks) stops.emplace_back(p, WaypointAction::kPick);
    stops.emplace_back(task.drop, WaypointAction::kDrop);
  }
  std::vector<double> work;
  for (const PlanTask& task : tasks) {
    work.insert(work.end(), task.picks.size(), task.work_time);
    work.push_back(task.drop_time);
  }

  double expected = t0;
  PointId at = start;
  std::size_t next = 0;
  for (std::size_t s = 0; s < stops.size(); ++s) {
    const Route r = routes_->Path(at, stops[s].first).value();
    expected += r.length / v;
    // Find the stop's waypoint.
    while (next < w.size() && w[next].action == WaypointAction::kMove) ++next;
    ASSERT_LT(next, w.size());
    EXPECT_EQ(w[next].point, stops[s].first) << "stop " << s;
    EXPECT_EQ(w[next].action, stops[s].second) << "stop " << s;
    EXPECT_NEAR(w[next].eta, expected, 1e-9) << "stop " << s;
    EXPECT_EQ(w[next].dwell, work[s]);
    expected += work[s];
    at = stops[s].first;
    ++next;
  }
  EXPECT_EQ(next, w.size());
  EXPECT_NEAR(plan->end_time(), expected, 1e-9);
  // Eq. (3): T_w = n_c * t_w with n_c = the picks (the seed's task points), plus the drop time.
  EXPECT_EQ(TaskPointCount(tasks[0]), 3);
  EXPECT_DOUBLE_EQ(TaskWorkTime(tasks[0]) + TaskWorkTime(tasks[1]), 3 * 5.0 + 2 * 3.0 + 2.0);
}

TEST_F(PlanTest, EveryRoutePointIsAWaypointJoinedByArcs) {
  const PointId start = map_->FindPoint("park-P7").value();
  const Result<Plan> plan =
      BuildPlan(*map_, *routes_, start, 0.0, 1.0, {{{Pick(19, 16.5)}, Drop(28, 20.75), 2.0}});
  ASSERT_TRUE(plan.ok()) << plan.error().message;
  const std::vector<Waypoint>& w = plan->waypoints;
  ASSERT_GE(w.size(), 3u);
  EXPECT_EQ(w.front().point, start);
  EXPECT_EQ(w.front().eta, 0.0);
  for (std::size_t i = 0; i < w.size(); ++i) {
    EXPECT_EQ(w[i].seq, static_cast<int>(i));
    EXPECT_EQ(w[i].xy, map_->point(w[i].point).position);
    if (i == 0) continue;
    EXPECT_GE(w[i].eta, w[i - 1].departure());
    if (w[i].point != w[i - 1].point) {
      const auto arc = map_->FindArc(w[i - 1].point, w[i].point);
      ASSERT_TRUE(arc.has_value()) << i;
      EXPECT_NEAR(w[i].eta - w[i - 1].departure(), map_->arc(*arc).length / 1.0, 1e-9);
    }
  }
}

TEST_F(PlanTest, NoTasksIsTheStartAlone) {
  const PointId start = map_->FindPoint("park-P3").value();
  const Result<Plan> plan = BuildPlan(*map_, *routes_, start, 7.0, 1.0, {});
  ASSERT_TRUE(plan.ok()) << plan.error().message;
  ASSERT_EQ(plan->waypoints.size(), 1u);
  EXPECT_EQ(plan->PositionAt(100.0), map_->point(start).position);
}

TEST_F(PlanTest, RejectsBadInput) {
  const PointId start = map_->FindPoint("park-P1").value();
  const PlanTask good{{Pick(19, 17)}, Drop(6.5, 2.75), 1.0};
  EXPECT_EQ(BuildPlan(*map_, *routes_, start, 0, 0.0, {good}).error().code,
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(BuildPlan(*map_, *routes_, start, 0, 1.0, {{{}, Drop(6.5, 2.75), 1.0}}).error().code,
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(BuildPlan(*map_, *routes_, start, 0, 1.0, {{{Pick(19, 17)}, Drop(6.5, 2.75), -1}})
                .error()
                .code,
            ErrorCode::kInvalidArgument);
  for (double drop_time : {-1.0, std::nan("")}) {
    const Result<Plan> bad = BuildPlan(*map_, *routes_, start, 0, 1.0, {{{Pick(19, 17)}, Drop(6.5, 2.75), 1.0, drop_time}});
    ASSERT_FALSE(bad.ok());
    EXPECT_EQ(bad.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(bad.error().message.find("drop time"), std::string::npos) << bad.error().message;
  }
  EXPECT_EQ(BuildPlan(*map_, *routes_, 100000, 0, 1.0, {good}).error().code, ErrorCode::kNotFound);
  EXPECT_EQ(BuildPlan(*map_, *routes_, start, 0, 1.0, {{{Pick(19, 17)}, 100000, 1.0}}).error().code,
            ErrorCode::kNotFound);
}

TEST(PlanUnreachableTest, NamesBothPoints) {
  // L -> K is one-way: nothing leads back from the pick K to L.
  MapBuilder b("oneway");
  b.AddRectZone("floor", {-1, -1}, {10, 1});
  b.AddPoint("L", {0, 0}, PointKind::kLane);
  b.AddPoint("K", {5, 0}, PointKind::kPick);
  b.AddPath("L", "K");
  const auto map = std::make_shared<const WarehouseMap>(b.Build().value());
  const auto routes = MakeRouteTable(map, {}).value();
  const PointId l = *map->FindPoint("L"), k = *map->FindPoint("K");
  const Result<Plan> plan = BuildPlan(*map, *routes, k, 0, 1.0, {{{l}, k, 1.0}});
  ASSERT_FALSE(plan.ok());
  EXPECT_EQ(plan.error().code, ErrorCode::kUnreachable);
  EXPECT_NE(plan.error().message.find("task 1, pick 1: no route from point 'K'"),
            std::string::npos)
      << plan.error().message;
  EXPECT_NE(plan.error().message.find("to point 'L'"), std::string::npos) << plan.error().message;
  // The other way round works.
  EXPECT_TRUE(BuildPlan(*map, *routes, l, 0, 1.0, {{{k}, k, 1.0}}).ok());
}

TEST(PlanPositionTest, InterpolatesBetweenDeparturesAndArrivalsAndHoldsDuringWork) {
  Plan plan;
  auto add = [&](double x, double y, double eta, WaypointAction a, double dwell) {
    Waypoint w;
    w.seq = static_cast<int>(plan.waypoints.size());
    w.xy = {x, y};
    w.eta = eta;
    w.action = a;
    w.dwell = dwell;
    plan.waypoints.push_back(w);
  };
  add(0, 0, 10, WaypointAction::kMove, 0);
  add(4, 0, 14, WaypointAction::kPick, 5);   // works 14..19
  add(4, 6, 25, WaypointAction::kMove, 0);
  add(4, 6, 25, WaypointAction::kDrop, 2);   // same point, works 25..27
  EXPECT_EQ(plan.PositionAt(-5), Eigen::Vector2d(0, 0));
  EXPECT_EQ(plan.PositionAt(10), Eigen::Vector2d(0, 0));
  EXPECT_TRUE(plan.PositionAt(11).isApprox(Eigen::Vector2d(1, 0)));
  EXPECT_TRUE(plan.PositionAt(13.5).isApprox(Eigen::Vector2d(3.5, 0)));
  EXPECT_EQ(plan.PositionAt(14), Eigen::Vector2d(4, 0));
  EXPECT_EQ(plan.PositionAt(16), Eigen::Vector2d(4, 0));  // working
  EXPECT_EQ(plan.PositionAt(19), Eigen::Vector2d(4, 0));
  EXPECT_TRUE(plan.PositionAt(22).isApprox(Eigen::Vector2d(4, 3)));
  EXPECT_EQ(plan.PositionAt(26), Eigen::Vector2d(4, 6));
  EXPECT_EQ(plan.PositionAt(1000), Eigen::Vector2d(4, 6));
  EXPECT_EQ(plan.start_time(), 10);
  EXPECT_EQ(plan.end_time(), 27);
  EXPECT_THROW(Plan{}.PositionAt(0), std::logic_error);
}

TEST(WaypointActionTest, NamesRoundTrip) {
  for (WaypointAction a : {WaypointAction::kMove, WaypointAction::kPick, WaypointAction::kDrop,
                           WaypointAction::kWait, WaypointAction::kPark, WaypointAction::kCharge}) {
    EXPECT_EQ(ParseWaypointAction(WaypointActionName(a)), a);
  }
  EXPECT_FALSE(ParseWaypointAction("fly").has_value());
}

// Wang2019's turning time: every heading change between consecutive arcs adds its share of
// turn_time (per 90 degrees) to the ETAs after it; without turns the plan is unchanged.
TEST_F(PlanTest, TurningTimeAddsItsShareAtEveryHeadingChange) {
  const PointId start = map_->FindPoint("park-P1").value();
  const std::vector<PlanTask> tasks = {{{Pick(29, 13)}, Drop(32.25, 5), 5.0}};
  const Plan plain = BuildPlan(*map_, *routes_, start, 0.0, 1.0, tasks).value();
  const Plan turning = BuildPlan(*map_, *routes_, start, 0.0, 1.0, tasks, 2.0).value();
  ASSERT_EQ(plain.waypoints.size(), turning.waypoints.size());
  double turned = 0.0;  // expected extra seconds so far
  for (std::size_t i = 2; i < plain.waypoints.size(); ++i) {
    const Waypoint& a = plain.waypoints[i - 2];
    const Waypoint& b = plain.waypoints[i - 1];
    const Waypoint& c = plain.waypoints[i];
    const Eigen::Vector2d u = b.xy - a.xy, v = c.xy - b.xy;
    if (u.norm() > 1e-9 && v.norm() > 1e-9) {
      turned += 2.0 * std::abs(std::atan2(u.x() * v.y() - u.y() * v.x(), u.dot(v))) / (M_PI / 2.0);
    }
    EXPECT_NEAR(turning.waypoints[i].eta - plain.waypoints[i].eta, turned, 1e-9) << i;
  }
  EXPECT_GT(turned, 2.0);  // the route turns at least once
  EXPECT_FALSE(BuildPlan(*map_, *routes_, start, 0.0, 1.0, tasks, -1.0).ok());
}

TEST(FindSequenceTest, FindsAWaypointInAPlanWithOrWithoutGapsOrOutOfOrder) {
  auto plan = [](std::vector<int> seqs) {
    std::vector<Waypoint> w;
    for (int s : seqs) {
      Waypoint x;
      x.seq = s;
      w.push_back(x);
    }
    return w;
  };
  const std::size_t none = static_cast<std::size_t>(-1);
  EXPECT_EQ(FindSequence(plan({4, 5, 6, 7}), 6), 2u);
  EXPECT_EQ(FindSequence(plan({4, 5, 6, 7}), 8), none);
  EXPECT_EQ(FindSequence(plan({4, 5, 6, 7}), 3), none);
  EXPECT_EQ(FindSequence(plan({2, 3, 9, 10, 11}), 10), 3u);  // re-planned: a gap
  EXPECT_EQ(FindSequence(plan({2, 3, 9, 10, 11}), 4), none);
  EXPECT_EQ(FindSequence(plan({7, 3, 5}), 5), 2u);  // out of order: still found
  EXPECT_EQ(FindSequence(plan({}), 0), none);
  EXPECT_EQ(FindSequence(plan({0, 1}), 1ull << 40), none);
}

}  // namespace
}  // namespace dispatch::engine
