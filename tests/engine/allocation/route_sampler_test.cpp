#include "engine/allocation/route_sampler.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "allocation_test_util.h"

namespace dispatch::engine {
namespace {

using testing_util::Grid;
using testing_util::Pt;
using testing_util::Routes;

TEST(RouteSamplerTest, LegSamplesEveryStepExcludingTheArrival) {
  auto map = Grid(5, 1, 1.0, 5, {{4, 0}}, {{0, 0}});
  auto routes = Routes(map);
  RouteSampler sampler(*map, *routes, 1.0, 0.5);
  std::vector<RouteSample> out;
  const double arrival = sampler.AppendLeg(Pt(*map, "0,0"), Pt(*map, "4,0"), 10.0, out);
  EXPECT_DOUBLE_EQ(arrival, 14.0);
  ASSERT_EQ(out.size(), 8u);  // 0, 0.5, ..., 3.5
  for (std::size_t k = 0; k < out.size(); ++k) {
    EXPECT_NEAR(out[k].xy.x(), 0.5 * k, 1e-12);
    EXPECT_NEAR(out[k].t, 10.0 + 0.5 * k, 1e-12);
  }
  out.clear();
  EXPECT_DOUBLE_EQ(sampler.AppendLeg(Pt(*map, "4,0"), Pt(*map, "4,0"), 3.0, out), 3.0);
  EXPECT_TRUE(out.empty());
}

// One way only: a -> m -> b along the x axis (4 m).
std::shared_ptr<const WarehouseMap> OneWay() {
  MapBuilder b("oneway");
  b.AddRectZone("z", {-1, -1}, {5, 1});
  b.AddPoint("a", {0, 0}, PointKind::kPick);
  b.AddPoint("m", {2, 0}, PointKind::kLane);
  b.AddPoint("b", {4, 0}, PointKind::kDrop);
  b.AddPath("a", "m");
  b.AddPath("m", "b");
  MapBuildOptions o;
  o.check_service_connectivity = false;
  return testing_util::Share(b.Build(o));
}

TEST(RouteSamplerTest, UnreachableLegIsInfinite) {
  auto map = OneWay();
  auto routes = Routes(map);
  RouteSampler sampler(*map, *routes, 1.0, 0.5);
  std::vector<RouteSample> out;
  EXPECT_TRUE(std::isinf(sampler.AppendLeg(Pt(*map, "b"), Pt(*map, "a"), 0.0, out)));
}

// Model test: every sample lies where BuildPlan's timed plan puts the robot at that time, the
// samples of each leg are h apart, and the task ends when the plan ends.
TEST(RouteSamplerTest, SamplesLieOnTheTimedPlan) {
  auto map = Grid(7, 6, 1.5, 3, {{1, 1}, {5, 4}, {6, 0}, {2, 5}}, {{0, 5}, {6, 5}});
  auto routes = Routes(map, 1.2);
  std::mt19937 rng(7);
  const std::vector<PointId> picks = {Pt(*map, "1,1"), Pt(*map, "5,4"), Pt(*map, "6,0"),
                                      Pt(*map, "2,5")};
  const std::vector<PointId> drops = {Pt(*map, "0,5"), Pt(*map, "6,5")};
  for (int trial = 0; trial < 30; ++trial) {
    const PointId start = static_cast<PointId>(rng() % map->point_count());
    PlanTask task;
    const int n = 1 + static_cast<int>(rng() % 3);
    for (int k = 0; k < n; ++k) task.picks.push_back(picks[rng() % picks.size()]);
    task.drop = drops[rng() % drops.size()];
    task.work_time = (rng() % 3) * 1.5;
    const double t0 = 3.0 + trial;
    const double h = trial % 2 ? 0.5 : 0.7;
    RouteSampler sampler(*map, *routes, 1.2, h);
    std::vector<RouteSample> out;
    const double arrival = sampler.AppendLeg(start, task.picks[0], t0, out);
    const double end = sampler.AppendTask(task, arrival, out);
    Result<Plan> plan = BuildPlan(*map, *routes, start, t0, 1.2, {task});
    ASSERT_TRUE(plan.ok());
    EXPECT_NEAR(end, plan->end_time(), 1e-9);
    ASSERT_FALSE(out.empty());
    for (std::size_t k = 0; k < out.size(); ++k) {
      EXPECT_LE((plan->PositionAt(out[k].t) - out[k].xy).norm(), 1e-9) << trial << " " << k;
      if (k > 0) {
        EXPECT_GE(out[k].t, out[k - 1].t - 1e-12);
        EXPECT_LE((out[k].xy - out[k - 1].xy).norm(), h + 1e-9);
      }
    }
  }
}

// TimeToTarget is AppendLeg's arrival without the samples, whichever order the legs to one
// target are asked in (the memo fills from any start), and +infinity where AppendLeg's is.
TEST(RouteSamplerTest, TimeToTargetIsTheLegsArrival) {
  auto map = Grid(7, 6, 1.5, 3, {{1, 1}, {5, 4}, {6, 0}, {2, 5}}, {{0, 5}, {6, 5}});
  auto routes = Routes(map, 1.2);
  std::mt19937 rng(11);
  RouteSampler timed(*map, *routes, 1.2, 0.5);
  RouteSampler sampled(*map, *routes, 1.2, 0.5);
  std::vector<RouteSample> out;
  for (int trial = 0; trial < 400; ++trial) {
    const PointId from = static_cast<PointId>(rng() % map->point_count());
    const PointId to = static_cast<PointId>(rng() % 3 == 0 ? 5 : rng() % map->point_count());
    out.clear();
    const double want = sampled.AppendLeg(from, to, 0.0, out);
    EXPECT_NEAR(timed.TimeToTarget(from, to), want, 1e-9 * (1.0 + want)) << from << " " << to;
  }
  // A rebound sampler forgets its memo (another table, the same answers as a fresh one).
  auto slow = Routes(map, 0.6);
  timed.Bind(*map, *slow, 0.6, 0.5);
  RouteSampler fresh(*map, *slow, 0.6, 0.5);
  out.clear();
  EXPECT_NEAR(timed.TimeToTarget(0, 5), fresh.AppendLeg(0, 5, 0.0, out), 1e-9);

  auto oneway = OneWay();
  auto oneway_routes = Routes(oneway);
  RouteSampler s(*oneway, *oneway_routes, 1.0, 0.5);
  EXPECT_DOUBLE_EQ(s.TimeToTarget(Pt(*oneway, "a"), Pt(*oneway, "b")), 4.0);
  EXPECT_DOUBLE_EQ(s.TimeToTarget(Pt(*oneway, "m"), Pt(*oneway, "b")), 2.0);  // memoised
  EXPECT_EQ(s.TimeToTarget(Pt(*oneway, "b"), Pt(*oneway, "b")), 0.0);
  EXPECT_TRUE(std::isinf(s.TimeToTarget(Pt(*oneway, "b"), Pt(*oneway, "a"))));
}

}  // namespace
}  // namespace dispatch::engine
