// CheckSafety on hand-made trajectories (Chu2024 eqs. (10)-(15)).
#include "engine/traffic/safety_check.h"

#include <gtest/gtest.h>

#include "engine/map/chu2024_floor.h"

namespace dispatch::engine {
namespace {

class SafetyCheckTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto m = BuildChu2024Floor();
    ASSERT_TRUE(m.ok()) << m.error().message;
    map_ = new WarehouseMap(std::move(m).value());
  }
  static void TearDownTestSuite() { delete map_; }
  static RobotSample Single(const std::string& id, Eigen::Vector2d xy) {
    return {id, id, id, false, xy};
  }
  static WarehouseMap* map_;
  TrafficConfig config_;
};
WarehouseMap* SafetyCheckTest::map_ = nullptr;

TEST_F(SafetyCheckTest, FindsRobotsTooClose) {
  std::vector<SafetyFrame> frames;
  for (int k = 0; k <= 13; ++k) {  // R2 drives into R1 from 1.5 m to 0.5 m, then stops
    const double x = 1.5 - 0.1 * std::min(k, 10);
    frames.push_back({0.1 * k, {Single("R1", {0, 0}), Single("R2", {x, 0})}});
  }
  const SafetyReport r = CheckSafety(frames, *map_, config_);
  ASSERT_EQ(r.violations.size(), 1u);  // one episode
  EXPECT_EQ(r.violations[0].kind, ViolationKind::kSpacing);
  EXPECT_NEAR(r.violations[0].t, 1.0, 1e-9);  // first frame below 0.6 m
  EXPECT_NEAR(r.violations[0].distance, 0.5, 1e-9);
  EXPECT_NEAR(r.violations[0].required, 0.6, 1e-12);
  EXPECT_NEAR(r.min_robot_distance, 0.5, 1e-9);
}

TEST_F(SafetyCheckTest, FormationMembersAreExemptFromEachOther) {
  const double df = config_.formation_radius;
  std::vector<RobotSample> robots;
  for (int i = 0; i < 3; ++i) {
    const double a = 2.0 * 3.14159265358979 * i / 3;
    robots.push_back({"R" + std::to_string(i + 1), "F:T1", "F:T1", true,
                      Eigen::Vector2d(df * std::cos(a), df * std::sin(a))});
  }
  SafetyReport r = CheckSafety({{0.0, robots}}, *map_, config_);
  EXPECT_TRUE(r.ok());
  EXPECT_TRUE(std::isinf(r.min_robot_distance));
  // A single robot 0.7 m from the front member is fine, 0.5 m is not.
  robots.push_back(Single("R4", {df + 0.7, 0}));
  EXPECT_TRUE(CheckSafety({{0.0, robots}}, *map_, config_).ok());
  robots.back().xy = {df + 0.5, 0};
  r = CheckSafety({{0.0, robots}}, *map_, config_);
  ASSERT_EQ(r.violations.size(), 1u);
  EXPECT_EQ(r.violations[0].b, "R4");
  EXPECT_EQ(r.violations[0].a, "R1");
}

// A robot may be in up to three groups (the team it approaches, the last two it left): it is
// exempt from the members of each, and only of those.
TEST_F(SafetyCheckTest, AnyOfThreeGroupsExempts) {
  RobotSample a = Single("R1", {0, 0});
  a.group = "team A";
  a.group2 = "team B";
  a.group3 = "team C";
  RobotSample b = Single("R2", {0.4, 0});
  for (const char* g : {"team A", "team B", "team C"}) {
    b.group = "R2";
    b.group3 = g;
    EXPECT_TRUE(CheckSafety({{0.0, {a, b}}}, *map_, config_).ok()) << g;
    b.group3.clear();
    b.group = g;
    EXPECT_TRUE(CheckSafety({{0.0, {a, b}}}, *map_, config_).ok()) << g;
  }
  b.group = "team D";
  EXPECT_EQ(CheckSafety({{0.0, {a, b}}}, *map_, config_).violations.size(), 1u);
}

TEST_F(SafetyCheckTest, FindsCrossingMovementsInsideOneIntersection) {
  // Two robots on opposite edges of one I_w (1.5 m apart: no spacing problem) with
  // different movements at the same time.
  const Intersection& in = map_->intersections()[8];
  Eigen::Vector2d lo = map_->point(in.inner[0]).position, hi = lo;
  for (PointId p : in.inner) {
    lo = lo.cwiseMin(map_->point(p).position);
    hi = hi.cwiseMax(map_->point(p).position);
  }
  ASSERT_NEAR(hi.x() - lo.x(), 1.5, 1e-9);
  std::vector<SafetyFrame> crossing, following;
  for (int k = 0; k <= 15; ++k) {
    const double f = 0.1 * k;
    crossing.push_back({f, {Single("R1", {lo.x() + f, lo.y()}),                // eastbound
                            Single("R2", {hi.x(), lo.y() + f})}});            // northbound
    following.push_back({f, {Single("R1", {lo.x() - 0.7 + f, lo.y()}),       // same movement,
                             Single("R2", {lo.x() + f, lo.y()})}});           // 0.7 m apart
  }
  const SafetyReport r = CheckSafety(crossing, *map_, config_);
  ASSERT_EQ(r.violations.size(), 1u) << r.violations[0].Describe();
  EXPECT_EQ(r.violations[0].kind, ViolationKind::kCrossing);
  EXPECT_EQ(r.violations[0].intersection, 8);
  const SafetyReport same = CheckSafety(following, *map_, config_);
  EXPECT_TRUE(same.ok()) << same.violations[0].Describe();
  // Members of one group (gathering for a formation) are exempt from the crossing rule too.
  for (auto& frame : crossing) {
    for (auto& robot : frame.robots) robot.group = "F:T9";
  }
  EXPECT_TRUE(CheckSafety(crossing, *map_, config_).ok());
}

TEST_F(SafetyCheckTest, OnlineFollowersMayDivergeButNotMerge) {
  // R1 and R2 enter one I_w by its south-west point 1 m apart, eastbound. R1 turns
  // north at the south-east point while R2 goes on east: they diverge, nobody crosses
  // (followers_may_diverge; the strict default calls it two movements).
  const Intersection& in = map_->intersections()[8];
  Eigen::Vector2d lo = map_->point(in.inner[0]).position;
  for (PointId p : in.inner) lo = lo.cwiseMin(map_->point(p).position);
  std::vector<SafetyFrame> diverging, merging;
  for (int k = 0; k <= 30; ++k) {
    const double f = 0.1 * k;
    const Eigen::Vector2d r1 = f <= 1.5 ? Eigen::Vector2d(lo.x() + f, lo.y()) : Eigen::Vector2d(lo.x() + 1.5, lo.y() + f - 1.5);
    diverging.push_back({f, {Single("R1", r1), Single("R2", {lo.x() - 1.0 + f, lo.y()})}});
    // R2 comes down to the north-west point instead and drives east to the north-east one,
    // where R1 leaves too: their paths merge.
    const Eigen::Vector2d r2 = f <= 0.7 ? Eigen::Vector2d(lo.x(), lo.y() + 2.2 - f) : Eigen::Vector2d(lo.x() + f - 0.7, lo.y() + 1.5);
    merging.push_back({f, {Single("R1", r1), Single("R2", r2)}});
  }
  EXPECT_FALSE(CheckSafety(diverging, *map_, config_).ok());  // strict by default
  SafetyCheckOptions online;
  online.followers_may_diverge = true;
  const SafetyReport same_entry = CheckSafety(diverging, *map_, config_, online);
  EXPECT_TRUE(same_entry.ok()) << same_entry.violations[0].Describe();
  const SafetyReport other_entry = CheckSafety(merging, *map_, config_, online);
  ASSERT_FALSE(other_entry.ok());
  EXPECT_EQ(other_entry.violations[0].kind, ViolationKind::kCrossing);
  // Cut off while R2 is still near the entry and R1 has driven on: the same.
  diverging.resize(13);
  EXPECT_TRUE(CheckSafety(diverging, *map_, config_, online).ok());
  EXPECT_FALSE(CheckSafety(diverging, *map_, config_).ok());
}

}  // namespace
}  // namespace dispatch::engine
