// TrafficPredictor's counts (Chu2024 eqs. (6)-(8)): a model test against recounts, traced
// plans moved by whole buckets, the density accumulator's variants against the model;
// SamplePlan. Density's peaks and flow on hand-made plans are in
// traffic_prediction_density_test.cpp, the zone lookup in traffic_prediction_zone_test.cpp.
#include "engine/allocation/traffic_prediction.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "engine/map/chu2024_floor.h"
#include "engine/map/map_builder.h"
#include "engine/routing/route_table.h"
#include "tests/engine/allocation/zone_test_support.h"

namespace dispatch::engine {
namespace {

using testing_zones::BruteForceZone;

TEST(TrafficPredictionConfigTest, RejectsBadSettings) {
  const WarehouseMap map = BuildChu2024Floor().value();
  TrafficPredictionConfig config;
  config.bucket_seconds = 0.0;
  EXPECT_THROW(TrafficPredictor(map, config), std::invalid_argument);
  config = {};
  config.zone_cell_size = -1.0;
  EXPECT_THROW(TrafficPredictor(map, config), std::invalid_argument);
  config = {};
  config.origin_time = std::nan("");
  EXPECT_THROW(TrafficPredictor(map, config), std::invalid_argument);
}

// --- Counts: model test -------------------------------------------------------------------

class TrafficPredictionModelTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    map_ = std::make_shared<const WarehouseMap>(BuildChu2024Floor().value());
    routes_ = std::shared_ptr<const RouteTable>(MakeRouteTable(map_, {}).value().release());
    for (PointId p = 0; p < static_cast<PointId>(map_->point_count()); ++p) {
      const PointKind kind = map_->point(p).kind;
      if (kind == PointKind::kPick) picks_.push_back(p);
      if (kind == PointKind::kDrop) drops_.push_back(p);
      if (kind == PointKind::kPark) parks_.push_back(p);
    }
  }

  // A hand-made plan: random points over the floor (some just outside it, in no zone),
  // dwells, repeated positions; or a BuildPlan over the route table.
  static Plan RandomPlan(std::mt19937& rng) {
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    const double start = -10.0 + 120.0 * u01(rng);
    if (u01(rng) < 0.4) {
      std::uniform_int_distribution<std::size_t> pick(0, picks_.size() - 1);
      std::uniform_int_distribution<std::size_t> drop(0, drops_.size() - 1);
      std::uniform_int_distribution<std::size_t> park(0, parks_.size() - 1);
      std::vector<PlanTask> tasks(1 + rng() % 2);
      for (PlanTask& t : tasks) {
        t.picks = {picks_[pick(rng)]};
        t.drop = drops_[drop(rng)];
        t.work_time = 3.0 * u01(rng);
      }
      return BuildPlan(*map_, *routes_, parks_[park(rng)], start, 1.0 + u01(rng), tasks).value();
    }
    Plan plan;
    const int n = 1 + static_cast<int>(rng() % 6);
    double t = start;
    for (int i = 0; i < n; ++i) {
      Waypoint w;
      w.seq = i;
      if (i > 0 && u01(rng) < 0.2) {
        w.xy = plan.waypoints.back().xy;  // standing still
      } else {
        w.xy = {-4.0 + 43.0 * u01(rng), -3.0 + 30.0 * u01(rng)};
      }
      if (i > 0) t += 0.01 + 20.0 * u01(rng);
      w.eta = t;
      w.dwell = u01(rng) < 0.5 ? 0.0 : 10.0 * u01(rng);
      t += w.dwell;
      plan.waypoints.push_back(w);
    }
    return plan;
  }

  // Recount from scratch by the documented rule: a plan counts at every s_b in
  // [start_time, end_time], in the zone BruteForceZone(PositionAt(s_b)).
  static void ExpectCountsMatch(const TrafficPredictor& pred,
                                const std::map<std::string, Plan>& plans, std::mt19937& rng) {
    const std::size_t n_zones = map_->zones().size();
    const std::size_t n_buckets = pred.bucket_count();
    const double origin = pred.config().origin_time, dt = pred.config().bucket_seconds;
    std::vector<int> expected(n_buckets * n_zones, 0);
    std::map<std::string, std::vector<ZoneId>> own;  // per robot, zone at each bucket or -1
    for (const auto& [robot, plan] : plans) {
      std::vector<ZoneId>& z_of = own[robot];
      z_of.assign(n_buckets, -1);
      for (std::size_t b = 0; b < n_buckets; ++b) {
        const double s = origin + static_cast<double>(b) * dt;
        if (s < plan.start_time() || s > plan.end_time()) continue;
        const ZoneId z = BruteForceZone(*map_, plan.PositionAt(s));
        z_of[b] = z;
        if (z >= 0) ++expected[b * n_zones + static_cast<std::size_t>(z)];
      }
      // Storage must reach the plan's last bucket start.
      if (plan.end_time() >= origin) {
        EXPECT_GT(origin + static_cast<double>(n_buckets) * dt, plan.end_time()) << robot;
      }
    }
    std::vector<std::string> robots = {"", "nobody"};
    for (const auto& [robot, plan] : plans) robots.push_back(robot);
    const std::string& excluded = robots[rng() % robots.size()];
    int mismatches = 0;
    for (std::size_t b = 0; b < n_buckets; ++b) {
      const double s = origin + static_cast<double>(b) * dt;
      for (std::size_t z = 0; z < n_zones; ++z) {
        const ZoneId zone = static_cast<ZoneId>(z);
        const int want = expected[b * n_zones + z];
        int want_excl = want;
        if (auto it = own.find(excluded); it != own.end() && it->second[b] == zone) --want_excl;
        // At the bucket start, inside the bucket, and excluding one robot.
        if (pred.CountAt(zone, s) != want || pred.CountAt(zone, s + 0.6 * dt) != want ||
            pred.CountAt(zone, s, excluded) != want_excl) {
          if (++mismatches <= 5) {
            ADD_FAILURE() << "bucket " << b << " zone " << z << ": " << pred.CountAt(zone, s)
                          << " want " << want << "; excluding '" << excluded
                          << "': " << pred.CountAt(zone, s, excluded) << " want " << want_excl;
          }
        }
      }
    }
    EXPECT_EQ(mismatches, 0);
    // Before the origin: bucket 0. Past the storage: nothing.
    for (std::size_t z = 0; z < n_zones && n_buckets > 0; ++z) {
      EXPECT_EQ(pred.CountAt(static_cast<ZoneId>(z), origin - 50.0), expected[z]);
    }
    EXPECT_EQ(pred.CountAt(0, origin + static_cast<double>(n_buckets + 1) * dt), 0);
    EXPECT_EQ(pred.CountAt(-1, origin), 0);
    EXPECT_EQ(pred.CountAt(static_cast<ZoneId>(n_zones), origin), 0);
  }

  static std::shared_ptr<const WarehouseMap> map_;
  static std::shared_ptr<const RouteTable> routes_;
  static std::vector<PointId> picks_, drops_, parks_;
};
std::shared_ptr<const WarehouseMap> TrafficPredictionModelTest::map_;
std::shared_ptr<const RouteTable> TrafficPredictionModelTest::routes_;
std::vector<PointId> TrafficPredictionModelTest::picks_;
std::vector<PointId> TrafficPredictionModelTest::drops_;
std::vector<PointId> TrafficPredictionModelTest::parks_;

TEST_F(TrafficPredictionModelTest, CountsEqualRecountAfterRandomSetReplaceRemove) {
  // A bucket length that is not a binary fraction and an origin that plans start before.
  const std::pair<double, double> settings[] = {{0.7, 3.1}, {0.5, 0.0}, {2.3, -7.0}};
  for (const auto& [dt, origin] : settings) {
    TrafficPredictionConfig config;
    config.bucket_seconds = dt;
    config.origin_time = origin;
    TrafficPredictor pred(*map_, config);
    std::map<std::string, Plan> model;
    std::mt19937 rng(static_cast<std::uint32_t>(1000 * dt));
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    for (int op = 0; op < 120; ++op) {
      const std::string robot = "R" + std::to_string(rng() % 8);
      const double r = u01(rng);
      if (r < 0.65) {
        Plan plan = RandomPlan(rng);
        if (u01(rng) < 0.3) {  // start exactly on a bucket start (rounding of the first bucket)
          const double target = origin + static_cast<double>(rng() % 150) * dt;
          const double shift = target - plan.start_time();
          for (Waypoint& w : plan.waypoints) w.eta += shift;
          plan.waypoints.front().eta = target;
        }
        pred.SetPlan(robot, plan);
        model[robot] = std::move(plan);
      } else if (r < 0.9) {
        pred.RemovePlan(robot);
        model.erase(robot);
      } else {
        pred.SetPlan(robot, Plan{});  // an empty plan removes
        model.erase(robot);
      }
      ASSERT_EQ(pred.robot_count(), model.size());
      ExpectCountsMatch(pred, model, rng);
      if (HasFailure()) return;
    }
  }
}

// A plan traced on a grid of its own (from an origin at or before its start, with a final
// hold) and set moved by whole buckets counts as the moved plan with the hold appended, set
// by SetPlan would. Times on a 1/16 s grid: moving them is exact.
TEST_F(TrafficPredictionModelTest, TracedPlansMovedByWholeBucketsCountAsTheMovedPlans) {
  TrafficPredictionConfig config;
  config.bucket_seconds = 0.5;
  TrafficPredictor pred(*map_, config);
  std::map<std::string, Plan> model;
  std::mt19937 rng(41);
  for (int op = 0; op < 80; ++op) {
    const std::string robot = "R" + std::to_string(rng() % 6);
    Plan plan = RandomPlan(rng);
    double departure = -1e9;
    for (Waypoint& w : plan.waypoints) {
      w.eta = std::max(std::round(w.eta * 16.0) / 16.0, departure);
      w.dwell = std::round(w.dwell * 16.0) / 16.0;
      departure = w.departure();
    }
    const double hold = 2.5 * static_cast<double>(rng() % 3);
    const std::size_t offset = rng() % 40;
    // The trace's origin: m buckets before 0, at or before the plan's start.
    const double m = std::max(0.0, std::ceil(-plan.start_time() / config.bucket_seconds));
    const double origin = -m * config.bucket_seconds;
    const TrafficPredictor::Contribution trace = pred.Trace(robot, plan, origin, hold);
    pred.SetTraced(robot, trace, offset);
    // Bucket j of the trace (time origin + j dt) is bucket j + offset: the plan moved (offset + m) dt.
    Plan moved = plan;
    for (Waypoint& w : moved.waypoints) w.eta += (static_cast<double>(offset) + m) * config.bucket_seconds;
    if (hold > 0.0) {
      Waypoint w = moved.waypoints.back();
      w.eta = w.departure();
      w.dwell = hold;
      w.action = WaypointAction::kWait;
      moved.waypoints.push_back(w);
    }
    model[robot] = std::move(moved);
    ExpectCountsMatch(pred, model, rng);
    if (HasFailure()) return;
  }
  EXPECT_THROW(pred.SetTraced("", TrafficPredictor::Contribution{}, 0), std::invalid_argument);
}

TEST_F(TrafficPredictionModelTest, PlanCountsAtEveryBucketStartWithinItsSpan) {
  TrafficPredictionConfig config;
  config.bucket_seconds = 1.0;
  TrafficPredictor pred(*map_, config);
  Plan plan;
  plan.waypoints = {{0, kNoPoint, {5, 5}, 2.0, WaypointAction::kPark, 1.0, {}, {}},  // Z1, 2 .. 3
                    {1, kNoPoint, {30, 5}, 8.0, WaypointAction::kMove, 0.0, {}, {}}};  // Z3 at 8
  pred.SetPlan("R1", plan);
  const ZoneId z1 = map_->FindZone("Z1").value(), z3 = map_->FindZone("Z3").value();
  EXPECT_EQ(pred.bucket_count(), 9u);  // buckets 2 .. 8
  EXPECT_EQ(pred.CountAt(z1, 1.99), 0);  // bucket 1 starts before the plan
  EXPECT_EQ(pred.CountAt(z1, 2.0), 1);
  EXPECT_EQ(pred.CountAt(z1, 3.5), 1);   // bucket 3, still standing at (5, 5)
  EXPECT_EQ(pred.CountAt(z3, 8.0), 1);
  EXPECT_EQ(pred.CountAt(z3, 8.9), 1);   // bucket 8 holds the position at s_8 = 8
  EXPECT_EQ(pred.CountAt(z3, 9.0), 0);   // after the end
  EXPECT_EQ(pred.CountAt(z1, 2.0, "R1"), 0);

  // A plan inside one bucket (no bucket start in its span) predicts nothing.
  Plan blip;
  blip.waypoints = {{0, kNoPoint, {5, 5}, 20.2, WaypointAction::kPark, 0.5, {}, {}}};
  pred.SetPlan("R2", blip);
  EXPECT_EQ(pred.CountAt(z1, 20.5), 0);
  EXPECT_EQ(pred.bucket_count(), 9u);

  Plan bad = plan;
  bad.waypoints.back().eta = std::numeric_limits<double>::infinity();
  EXPECT_THROW(pred.SetPlan("R3", bad), std::invalid_argument);
  EXPECT_THROW(pred.SetPlan("", plan), std::invalid_argument);
  EXPECT_EQ(pred.CountAt(z1, 2.0), 1);  // unchanged by the rejected calls
}

// --- SamplePlan ---------------------------------------------------------------------------

Plan ThreeWaypointPlan() {
  Plan plan;
  // 3 m east at 1 m/s after a 2 s dwell, a 4 s pick, 4 m north at 0.5 m/s, a 1 s drop.
  plan.waypoints = {{0, kNoPoint, {0, 0}, 10.0, WaypointAction::kMove, 2.0, {}, {}},
                    {1, kNoPoint, {3, 0}, 15.0, WaypointAction::kPick, 4.0, {}, {}},
                    {2, kNoPoint, {3, 4}, 27.0, WaypointAction::kDrop, 1.0, {}, {}}};
  return plan;
}

void ExpectSample(const RouteSample& s, double x, double y, double t) {
  EXPECT_NEAR(s.xy.x(), x, 1e-12);
  EXPECT_NEAR(s.xy.y(), y, 1e-12);
  EXPECT_NEAR(s.t, t, 1e-12);
}

TEST(SamplePlanTest, SpacingFirstLastAndDwellAwareTimes) {
  const Plan plan = ThreeWaypointPlan();
  const std::vector<RouteSample> s = SamplePlan(plan, 2.0);
  ASSERT_EQ(s.size(), 5u);
  ExpectSample(s[0], 0, 0, 10.0);  // first waypoint at its eta
  ExpectSample(s[1], 2, 0, 14.0);  // departs at 12, 2 m at 1 m/s
  ExpectSample(s[2], 3, 1, 21.0);  // the pick's dwell: departs at 19, 1 m at 0.5 m/s
  ExpectSample(s[3], 3, 3, 25.0);
  ExpectSample(s[4], 3, 4, 27.0);  // last waypoint at its eta

  // A sample landing on a waypoint takes its arrival time; the next one is after the dwell.
  const std::vector<RouteSample> u = SamplePlan(plan, 1.0);
  ASSERT_EQ(u.size(), 8u);  // 0..7 m; the last sample is the last waypoint, not repeated
  ExpectSample(u[3], 3, 0, 15.0);
  ExpectSample(u[4], 3, 1, 21.0);
  ExpectSample(u[7], 3, 4, 27.0);

  // A step longer than the path: first and last only.
  const std::vector<RouteSample> v = SamplePlan(plan, 100.0);
  ASSERT_EQ(v.size(), 2u);
  ExpectSample(v[0], 0, 0, 10.0);
  ExpectSample(v[1], 3, 4, 27.0);
}

TEST(SamplePlanTest, DegeneratePlans) {
  EXPECT_TRUE(SamplePlan(Plan{}, 1.0).empty());
  Plan one;
  one.waypoints = {{0, kNoPoint, {1, 2}, 5.0, WaypointAction::kPark, 10.0, {}, {}}};
  const std::vector<RouteSample> s = SamplePlan(one, 0.5);
  ASSERT_EQ(s.size(), 1u);
  ExpectSample(s[0], 1, 2, 5.0);

  // Standing still between two waypoints (same xy): no extra samples, time keeps moving.
  Plan still = ThreeWaypointPlan();
  still.waypoints.insert(still.waypoints.begin() + 2,
                         {2, kNoPoint, {3, 0}, 20.0, WaypointAction::kWait, 0.0, {}, {}});
  still.waypoints[3].eta = 28.0;  // departs the wait at 20, 4 m in 8 s
  const std::vector<RouteSample> w = SamplePlan(still, 2.0);
  ASSERT_EQ(w.size(), 5u);
  ExpectSample(w[2], 3, 1, 22.0);
  ExpectSample(w[4], 3, 4, 28.0);

  EXPECT_THROW(SamplePlan(one, 0.0), std::invalid_argument);
  EXPECT_THROW(SamplePlan(one, std::nan("")), std::invalid_argument);
}

TEST(SamplePlanTest, ReusesTheCallersBuffer) {
  const Plan plan = ThreeWaypointPlan();
  std::vector<RouteSample> out;
  SamplePlan(plan, 0.5, &out);
  ASSERT_EQ(out.size(), 15u);
  const RouteSample* data = out.data();
  const std::size_t capacity = out.capacity();
  SamplePlan(plan, 1.0, &out);
  EXPECT_EQ(out.size(), 8u);
  EXPECT_EQ(out.data(), data);  // no reallocation
  EXPECT_EQ(out.capacity(), capacity);
}

// The accumulator's variants against Density: one reused through Reset, built from the handle
// SetPlan returns, or from Find, gives Density's peaks and flow; Flow() is Finish().flow; a
// sample added with AddAtMost at a time off by at most its slack never raises a peak above
// the exact sample's (the auction's lower bound of F rests on this), and equals it when the
// window holds one bucket.
TEST_F(TrafficPredictionModelTest, AccumulatorVariantsAndLowerBounds) {
  TrafficPredictionConfig config;
  config.bucket_seconds = 0.7;
  config.origin_time = 3.1;
  TrafficPredictor pred(*map_, config);
  std::mt19937 rng(4242);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::map<std::string, TrafficPredictor::PlanHandle> handles;
  for (int r = 0; r < 12; ++r) {
    const std::string robot = "R" + std::to_string(r);
    handles[robot] = pred.SetPlan(robot, RandomPlan(rng));
  }
  handles["R3"] = pred.SetPlan("R3", RandomPlan(rng));  // a replaced plan's new handle
  TrafficPredictor::DensityAccumulator reused(pred, TrafficPredictor::PlanHandle{});
  TrafficPredictor::DensityAccumulator bound(pred, TrafficPredictor::PlanHandle{});
  for (int trial = 0; trial < 300; ++trial) {
    const std::string robot = "R" + std::to_string(rng() % 13);  // R12: no plan
    std::vector<RouteSample> samples(1 + rng() % 40);
    double t = -5.0 + 150.0 * u01(rng);
    for (RouteSample& x : samples) {
      x.xy = {-4.0 + 43.0 * u01(rng), -3.0 + 30.0 * u01(rng)};
      x.t = t;
      t += 2.0 * u01(rng);
    }
    const DensityTerm want = pred.Density(samples, robot);
    const auto h = handles.count(robot) != 0 ? handles[robot] : TrafficPredictor::PlanHandle{};
    reused.Reset(h);
    TrafficPredictor::DensityAccumulator found(pred, pred.Find(robot));
    bound.Reset(h);
    const double slack = trial % 3 == 0 ? 1e-9 : 0.4 * u01(rng);
    for (const RouteSample& x : samples) {
      const ZoneId z = pred.ZoneAt(x.xy);
      reused.Add(z, x.t);
      found.Add(z, x.t);
      bound.AddAtMost(z, x.t + slack * (2.0 * u01(rng) - 1.0), slack);
    }
    const DensityTerm got = reused.Finish();
    EXPECT_EQ(got.peaks, want.peaks) << trial;
    EXPECT_EQ(got.flow, want.flow) << trial;
    EXPECT_EQ(found.Finish().peaks, want.peaks) << trial;
    EXPECT_EQ(reused.Flow(), want.flow) << trial;
    const DensityTerm low = bound.Finish();
    EXPECT_LE(bound.Flow(), want.flow) << trial;
    ASSERT_EQ(low.peaks.size(), want.peaks.size()) << trial;  // the same zones
    for (std::size_t k = 0; k < low.peaks.size(); ++k) {
      EXPECT_EQ(low.peaks[k].first, want.peaks[k].first);
      EXPECT_LE(low.peaks[k].second, want.peaks[k].second) << trial;
    }
    if (HasFailure()) return;
  }
  // One bucket in every window (slack far below the bucket, times mid-bucket): exact.
  for (int trial = 0; trial < 100; ++trial) {
    const std::string robot = "R" + std::to_string(rng() % 12);
    std::vector<RouteSample> samples(1 + rng() % 20);
    for (RouteSample& x : samples) {
      x.xy = {-4.0 + 43.0 * u01(rng), -3.0 + 30.0 * u01(rng)};
      x.t = config.origin_time + (static_cast<double>(rng() % 300) + 0.5) * config.bucket_seconds;
    }
    bound.Reset(handles[robot]);
    for (const RouteSample& x : samples) bound.AddAtMost(pred.ZoneAt(x.xy), x.t, 1e-6);
    EXPECT_EQ(bound.Finish().peaks, pred.Density(samples, robot).peaks) << trial;
  }
}

// Every sample is where the plan is at the sample's time; consecutive samples are `step`
// apart along the path (so at most `step` in a straight line); the count is
// floor(length / step) + 1 plus the last waypoint unless a sample already landed on it.
TEST_F(TrafficPredictionModelTest, SamplesLieOnThePlanAtTheirTimes) {
  std::mt19937 rng(99);
  for (int trial = 0; trial < 300; ++trial) {
    Plan plan = RandomPlan(rng);
    // Legs with movement need time for PositionAt to be defined along them.
    for (std::size_t i = 1; i < plan.waypoints.size(); ++i) {
      Waypoint& w = plan.waypoints[i];
      const double dep = plan.waypoints[i - 1].departure();
      if (w.eta <= dep) {
        const double shift = dep + 0.5 - w.eta;
        for (std::size_t j = i; j < plan.waypoints.size(); ++j) plan.waypoints[j].eta += shift;
      }
    }
    const double step = 0.3 + 3.0 * (rng() % 100) / 100.0;
    const std::vector<RouteSample> s = SamplePlan(plan, step);
    double length = 0.0;
    for (std::size_t i = 0; i + 1 < plan.waypoints.size(); ++i) {
      length += (plan.waypoints[i + 1].xy - plan.waypoints[i].xy).norm();
    }
    const std::size_t on_grid = static_cast<std::size_t>(std::floor(length / step + 1e-9)) + 1;
    ASSERT_GE(s.size(), on_grid);
    ASSERT_LE(s.size(), on_grid + 1);
    ExpectSample(s.front(), plan.waypoints.front().xy.x(), plan.waypoints.front().xy.y(),
                 plan.start_time());
    ExpectSample(s.back(), plan.waypoints.back().xy.x(), plan.waypoints.back().xy.y(),
                 plan.waypoints.back().eta);
    for (std::size_t k = 0; k < s.size(); ++k) {
      EXPECT_LT((plan.PositionAt(s[k].t) - s[k].xy).norm(), 1e-9) << "trial " << trial;
      if (k > 0) {
        EXPECT_GE(s[k].t, s[k - 1].t);
        EXPECT_LE((s[k].xy - s[k - 1].xy).norm(), step + 1e-9);
      }
    }
    if (HasFailure()) return;
  }
}

}  // namespace
}  // namespace dispatch::engine
