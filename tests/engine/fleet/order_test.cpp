#include "engine/fleet/order.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <string>

#include "engine/map/chu2024_floor.h"
#include "engine/map/map_builder.h"

namespace dispatch::engine {
namespace {

const std::vector<OrderState> kAllStates = {OrderState::kAccepted,  OrderState::kAssigned,
                                            OrderState::kInProgress, OrderState::kCompleted,
                                            OrderState::kCancelled, OrderState::kFailed};

TEST(OrderStateTest, NamesRoundTrip) {
  for (OrderState s : kAllStates) EXPECT_EQ(ParseOrderState(OrderStateName(s)), s);
  EXPECT_STREQ(OrderStateName(OrderState::kInProgress), "in_progress");
  EXPECT_FALSE(ParseOrderState("done").has_value());
  EXPECT_FALSE(ParseOrderState("").has_value());
}

TEST(OrderStateTest, OnlyTheLifecycleTransitionsAreAllowed) {
  using S = OrderState;
  const std::set<std::pair<S, S>> allowed = {
      {S::kAccepted, S::kAssigned},    {S::kAccepted, S::kCancelled},
      {S::kAccepted, S::kFailed},      {S::kAssigned, S::kInProgress},
      {S::kAssigned, S::kAccepted},    {S::kAssigned, S::kCancelled},
      {S::kAssigned, S::kFailed},      {S::kInProgress, S::kCompleted},
      {S::kInProgress, S::kCancelled}, {S::kInProgress, S::kFailed}};
  for (S from : kAllStates) {
    for (S to : kAllStates) {
      EXPECT_EQ(CanTransition(from, to), allowed.count({from, to}) == 1)
          << OrderStateName(from) << " -> " << OrderStateName(to);
    }
  }
  EXPECT_TRUE(IsTerminal(S::kFailed));
  EXPECT_FALSE(IsTerminal(S::kInProgress));
}

class ResolveOrderTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    map_ = std::make_shared<const WarehouseMap>(BuildChu2024Floor().value());
  }
  static OrderRequest Request(std::vector<StopSpec> picks, StopSpec drop) {
    OrderRequest r;
    r.id = "T1";
    r.picks = std::move(picks);
    r.drop = std::move(drop);
    return r;
  }
  static std::shared_ptr<const WarehouseMap> map_;
};
std::shared_ptr<const WarehouseMap> ResolveOrderTest::map_;

TEST_F(ResolveOrderTest, ExactCoordinatesResolveToPointsOfTheRightKind) {
  OrderRequest r = Request({Eigen::Vector2d(19, 17), Eigen::Vector2d(20.5, 10.5)},
                           Eigen::Vector2d(6.5, 2.75));
  r.formation = true;
  r.priority = 3;
  r.work_time = 4.0;
  const Result<Order> order = ResolveOrder(*map_, r);
  ASSERT_TRUE(order.ok()) << order.error().message;
  ASSERT_EQ(order->picks.size(), 2u);
  EXPECT_EQ(map_->point(order->picks[0]).kind, PointKind::kPick);
  EXPECT_TRUE(map_->point(order->picks[0]).position.isApprox(Eigen::Vector2d(19, 17)));
  EXPECT_TRUE(map_->point(order->picks[1]).position.isApprox(Eigen::Vector2d(20.5, 10.5)));
  EXPECT_EQ(map_->point(order->drop).kind, PointKind::kDrop);
  EXPECT_TRUE(map_->point(order->drop).position.isApprox(Eigen::Vector2d(6.5, 2.75)));
  EXPECT_EQ(order->state, OrderState::kAccepted);
  EXPECT_EQ(order->team_size(), kFormationTeamSize);
  EXPECT_EQ(order->priority, 3);
  EXPECT_EQ(order->work_time, 4.0);
}

TEST_F(ResolveOrderTest, CoordinateWithinToleranceSnaps) {
  const Result<Order> order =
      ResolveOrder(*map_, Request({Eigen::Vector2d(20.5 + 0.12, 10.5 - 0.1)},
                                  Eigen::Vector2d(6.5 - 0.15, 2.75)));
  ASSERT_TRUE(order.ok()) << order.error().message;
  EXPECT_TRUE(map_->point(order->picks[0]).position.isApprox(Eigen::Vector2d(20.5, 10.5)));
  EXPECT_TRUE(map_->point(order->drop).position.isApprox(Eigen::Vector2d(6.5, 2.75)));
}

TEST_F(ResolveOrderTest, CoordinateOutsideToleranceNamesCoordinateCandidateAndDistance) {
  const Result<Order> order =
      ResolveOrder(*map_, Request({Eigen::Vector2d(20.5, 10.85)}, Eigen::Vector2d(6.5, 2.75)));
  ASSERT_FALSE(order.ok());
  EXPECT_EQ(order.error().code, ErrorCode::kInvalidArgument);
  const PointId nearest = map_->NearestPoint({20.5, 10.5}, PointKind::kPick);
  const std::string& msg = order.error().message;
  EXPECT_NE(msg.find("(20.5, 10.85)"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'" + map_->point(nearest).name + "'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("0.35 m"), std::string::npos) << msg;
  EXPECT_NE(msg.find("pick 1"), std::string::npos) << msg;
  // The same spot is fine with a larger tolerance.
  EXPECT_TRUE(ResolveOrder(*map_, Request({Eigen::Vector2d(20.5, 10.85)},
                                          Eigen::Vector2d(6.5, 2.75)),
                           SnapOptions{0.4})
                  .ok());
}

TEST_F(ResolveOrderTest, SnapsOnlyToTheRequiredKind) {
  // A pick coordinate given as the drop: no drop point near it.
  const Result<Order> order =
      ResolveOrder(*map_, Request({Eigen::Vector2d(19, 17)}, Eigen::Vector2d(19, 17)));
  ASSERT_FALSE(order.ok());
  EXPECT_NE(order.error().message.find("drop"), std::string::npos) << order.error().message;
}

// The default tolerance is below half the closest spacing of two points of one kind, so a
// snap on the Chu2024 floor can never be ambiguous.
TEST_F(ResolveOrderTest, DefaultToleranceIsBelowHalfTheClosestSpacing) {
  for (PointKind kind : {PointKind::kPick, PointKind::kDrop}) {
    double closest = std::numeric_limits<double>::infinity();
    const auto& pts = map_->points();
    for (std::size_t i = 0; i < pts.size(); ++i) {
      for (std::size_t j = i + 1; j < pts.size(); ++j) {
        if (pts[i].kind == kind && pts[j].kind == kind) {
          closest = std::min(closest, (pts[i].position - pts[j].position).norm());
        }
      }
    }
    EXPECT_LT(SnapOptions{}.tolerance, closest / 2) << PointKindName(kind);
  }
}

TEST_F(ResolveOrderTest, AmbiguousSnapIsAnError) {
  // Between the dock (14, 16.5) and the lane pick (14, 17).
  const Result<Order> order = ResolveOrder(
      *map_, Request({Eigen::Vector2d(14, 16.75)}, Eigen::Vector2d(6.5, 2.75)), SnapOptions{1.0});
  ASSERT_FALSE(order.ok());
  EXPECT_NE(order.error().message.find("ambiguous"), std::string::npos) << order.error().message;
}

TEST_F(ResolveOrderTest, PointNames) {
  const PointId pick = map_->NearestPoint({19, 17}, PointKind::kPick);
  const PointId drop = map_->NearestPoint({6.5, 2.75}, PointKind::kDrop);
  const Result<Order> ok =
      ResolveOrder(*map_, Request({map_->point(pick).name}, map_->point(drop).name));
  ASSERT_TRUE(ok.ok()) << ok.error().message;
  EXPECT_EQ(ok->picks, std::vector<PointId>{pick});
  EXPECT_EQ(ok->drop, drop);

  const Result<Order> unknown =
      ResolveOrder(*map_, Request({std::string("no-such-point")}, map_->point(drop).name));
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.error().code, ErrorCode::kNotFound);
  EXPECT_NE(unknown.error().message.find("'no-such-point'"), std::string::npos);

  // A pick point named as the drop.
  const Result<Order> wrong_kind =
      ResolveOrder(*map_, Request({map_->point(pick).name}, map_->point(pick).name));
  ASSERT_FALSE(wrong_kind.ok());
  EXPECT_EQ(wrong_kind.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(wrong_kind.error().message.find("not a drop point"), std::string::npos)
      << wrong_kind.error().message;
}

TEST_F(ResolveOrderTest, RejectsEmptyPicksAndBadWorkTime) {
  const Result<Order> empty = ResolveOrder(*map_, Request({}, Eigen::Vector2d(6.5, 2.75)));
  ASSERT_FALSE(empty.ok());
  EXPECT_NE(empty.error().message.find("no pick points"), std::string::npos);
  for (double t_w : {0.0, -1.0, std::nan(""), kMaxWorkTime * 2}) {
    OrderRequest r = Request({Eigen::Vector2d(19, 17)}, Eigen::Vector2d(6.5, 2.75));
    r.work_time = t_w;
    const Result<Order> bad = ResolveOrder(*map_, r);
    ASSERT_FALSE(bad.ok()) << t_w;
    EXPECT_NE(bad.error().message.find("work time"), std::string::npos);
  }
  for (double release : {1e300, -1e300, std::nan(""), kMaxReleaseTime * 1.5}) {
    OrderRequest r = Request({Eigen::Vector2d(19, 17)}, Eigen::Vector2d(6.5, 2.75));
    r.release_time = release;
    const Result<Order> bad = ResolveOrder(*map_, r);
    ASSERT_FALSE(bad.ok()) << release;
    EXPECT_NE(bad.error().message.find("release time"), std::string::npos) << bad.error().message;
  }
  OrderRequest later = Request({Eigen::Vector2d(19, 17)}, Eigen::Vector2d(6.5, 2.75));
  later.release_time = 3600.0;  // an hour on: fine
  EXPECT_TRUE(ResolveOrder(*map_, later).ok());
  const Result<Order> nan_xy = ResolveOrder(
      *map_, Request({Eigen::Vector2d(std::nan(""), 1.0)}, Eigen::Vector2d(6.5, 2.75)));
  ASSERT_FALSE(nan_xy.ok());
  EXPECT_NE(nan_xy.error().message.find("not finite"), std::string::npos);
}


// Issue 17 §3: a stop may ask for a heading, only where a robot can choose its pose (a point in
// a free-space region) and only in a single-robot order; it is stored wrapped into (-pi, pi].
TEST(ResolveOrderHeadingTest, AHeadingIsKeptAtAFreeSpacePointAndRefusedElsewhere) {
  MapBuilder b("bay");
  b.SetFloor({0, 0}, {10, 4});
  b.AddRectZone("z", {0, 0}, {10, 4});
  b.AddPoint("w", {1.5, 0.8}, PointKind::kLane);
  b.AddPoint("K", {6.5, 0.8}, PointKind::kPick);
  b.AddPoint("L", {1.5, 2.0}, PointKind::kPick);
  b.AddPoint("D", {1.5, 2.8}, PointKind::kDrop);
  b.AddPath("w", "K", std::nullopt, 0.0, true);
  b.AddPath("w", "L", std::nullopt, 0.0, true);
  b.AddPath("L", "D", std::nullopt, 0.0, true);
  b.AddFreeSpace("bay", {{2, 0.1}, {8, 0.1}, {8, 1.5}, {2, 1.5}});
  auto built = b.Build();
  ASSERT_TRUE(built.ok()) << built.error().message;
  const WarehouseMap& map = *built;
  auto request = [](std::map<std::size_t, double> headings) {
    OrderRequest r;
    r.id = "o1";
    r.picks = {std::string("K"), std::string("L")};
    r.drop = std::string("D");
    r.stop_headings = std::move(headings);
    return r;
  };
  const double pi = std::numbers::pi;
  const Result<Order> kept = ResolveOrder(map, request({{0, 3 * pi}}));
  ASSERT_TRUE(kept.ok()) << kept.error().message;
  ASSERT_EQ(kept->stop_headings.size(), 1u);
  EXPECT_NEAR(kept->stop_headings.at(0), pi, 1e-9);  // 3 pi wrapped
  EXPECT_TRUE(ResolveOrder(map, request({})).ok());

  auto refused = [&](OrderRequest r, const std::string& why) {
    const Result<Order> o = ResolveOrder(map, r);
    ASSERT_FALSE(o.ok()) << why;
    EXPECT_EQ(o.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(o.error().message.find(why), std::string::npos) << o.error().message;
  };
  refused(request({{1, 0.0}}), "pick 2: a heading can only be given at a point inside a free-space region; 'L'");
  refused(request({{2, 0.0}}), "drop: a heading can only be given");
  refused(request({{3, 0.0}}), "a heading for stop 4 of 3");
  refused(request({{0, std::nan("")}}), "pick 1: heading must be finite");
  refused(request({{0, std::numeric_limits<double>::infinity()}}), "heading must be finite");
  OrderRequest team = request({{0, 0.0}});
  team.formation = true;
  refused(team, "a formation order's stops cannot ask for a heading");
}

}  // namespace
}  // namespace dispatch::engine
