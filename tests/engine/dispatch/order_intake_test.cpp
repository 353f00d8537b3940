// Order intake: the one validation of an order request, its errors naming the order.
#include "engine/dispatch/order_intake.h"

#include <gtest/gtest.h>

#include "engine/dispatch/strategy.h"
#include "tests/engine/dispatch/dispatch_test_support.h"

namespace dispatch::engine {
namespace {

using testing_util::Chu2024;
using testing_util::Chu2024Routes;
using testing_util::PointsOfKind;

OrderRequest Request(const std::string& client_id) {
  const auto& map = *Chu2024();
  OrderRequest r;
  r.client_id = client_id;
  r.picks = {map.point(PointsOfKind(map, PointKind::kPick).at(0)).name,
             map.point(PointsOfKind(map, PointKind::kPick).at(5)).name};
  r.drop = map.point(PointsOfKind(map, PointKind::kDrop).at(2)).position;
  r.created_time = 12.5;
  return r;
}

Error Refused(const OrderRequest& r) {
  auto admitted = AdmitOrder(*Chu2024(), *Chu2024Routes(), r, {}, "ord-000001");
  EXPECT_FALSE(admitted.ok());
  return admitted.ok() ? Error{} : admitted.error();
}

TEST(OrderIntake, AdmitsAResolvedReachableOrderUnderItsNewId) {
  const auto& map = *Chu2024();
  auto admitted = AdmitOrder(map, *Chu2024Routes(), Request("wms-1"), {}, "ord-000007");
  ASSERT_TRUE(admitted.ok()) << admitted.error().message;
  EXPECT_EQ(admitted->id, "ord-000007");
  EXPECT_EQ(admitted->client_id, "wms-1");
  EXPECT_EQ(admitted->created_time, 12.5);
  EXPECT_EQ(admitted->state, OrderState::kAccepted);
  ASSERT_EQ(admitted->picks.size(), 2u);
  EXPECT_EQ(admitted->picks[0], PointsOfKind(map, PointKind::kPick).at(0));
  EXPECT_EQ(admitted->drop, PointsOfKind(map, PointKind::kDrop).at(2));
  const std::vector<PointId> stops = StopsOf(map, Request("wms-1"), {});
  EXPECT_EQ(stops, (std::vector<PointId>{admitted->picks[0], admitted->picks[1], admitted->drop}));
}

TEST(OrderIntake, RefusesMissingOrOverlongClientIds) {
  Error e = Refused(Request(""));
  EXPECT_EQ(e.code, ErrorCode::kInvalidArgument);
  EXPECT_EQ(e.message, "client_order_id is required");
  e = Refused(Request(std::string(kMaxClientIdBytes + 1, 'x')));
  EXPECT_NE(e.message.find("longer than 128 bytes"), std::string::npos) << e.message;
  auto ok = AdmitOrder(*Chu2024(), *Chu2024Routes(), Request(std::string(kMaxClientIdBytes, 'x')), {}, "o");
  EXPECT_TRUE(ok.ok());
}

TEST(OrderIntake, RefusesTooManyPicksAndNamesTheOrder) {
  OrderRequest r = Request("big");
  r.picks.assign(kMaxPicksPerOrder + 1, r.picks.front());
  const Error e = Refused(r);
  EXPECT_NE(e.message.find("order 'big' has 101 picks; at most 100"), std::string::npos) << e.message;
  EXPECT_TRUE(StopsOf(*Chu2024(), r, {}).empty());
}

TEST(OrderIntake, StopErrorsNameTheClientsOrder) {
  OrderRequest r = Request("far");
  r.picks = {Eigen::Vector2d(-50.0, -50.0)};
  const Error e = Refused(r);
  EXPECT_EQ(e.code, ErrorCode::kInvalidArgument);
  EXPECT_NE(e.message.find("'far'"), std::string::npos) << e.message;
  EXPECT_TRUE(StopsOf(*Chu2024(), r, {}).empty());
  r = Request("slow");
  r.work_time = kMaxWorkTime * 2;
  EXPECT_EQ(Refused(r).code, ErrorCode::kInvalidArgument);
}

TEST(Strategy, MakesTheKnownStrategiesAndNamesThemForOthers) {
  for (const std::string& name : AllocatorNames()) {
    auto made = MakeAllocator(name);
    ASSERT_TRUE(made.ok()) << name;
    EXPECT_EQ((*made)->name().substr(0, name.size()), name);
  }
  auto unknown = MakeAllocator("pso-ga");
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.error().message, "unknown strategy 'pso-ga' (auction | greedy | exact | psoga)");
}

}  // namespace
}  // namespace dispatch::engine
