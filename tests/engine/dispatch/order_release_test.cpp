// Taking orders back from robots: the orders behind them go back for re-allocation.
#include "engine/dispatch/order_release.h"

#include <gtest/gtest.h>

namespace dispatch::engine {
namespace {

Waypoint At(PointId p, WaypointAction action = WaypointAction::kMove) {
  Waypoint w;
  w.point = p;
  w.action = action;
  return w;
}

// A plan serving `orders` in turn: a move and a drop each, after the anchor.
Assignment PlanOf(const std::string& robot, const std::vector<std::string>& orders) {
  Assignment a;
  a.robot_id = robot;
  for (std::size_t k = 0; k < orders.size(); ++k) {
    std::vector<Waypoint> seg = {At(1), At(2, WaypointAction::kDrop)};
    if (k == 0) seg.insert(seg.begin(), At(0));
    AppendOrder(a, orders[k], seg, 0.0, false, 0.0);
  }
  return a;
}

struct Book {
  std::map<std::string, OrderState> states;
  std::map<std::string, std::vector<std::string>> robots;
  std::map<std::string, Assignment> plans;
  ReleaseLookups Lookups() const {
    ReleaseLookups l;
    l.state = [this](const std::string& id) -> std::optional<OrderState> {
      auto it = states.find(id);
      return it == states.end() ? std::nullopt : std::optional<OrderState>(it->second);
    };
    l.robots = [this](const std::string& id) {
      auto it = robots.find(id);
      return it == robots.end() ? std::vector<std::string>{} : it->second;
    };
    l.assignment = [this](const std::string& r) -> const Assignment* {
      auto it = plans.find(r);
      return it == plans.end() ? nullptr : &it->second;
    };
    return l;
  }
};

Book TwoRobots() {
  // R1: o1 (started), o2, f (a formation with R2); R2: f, o3.
  Book b;
  b.states = {{"o1", OrderState::kInProgress}, {"o2", OrderState::kAssigned}, {"f", OrderState::kAssigned},
              {"o3", OrderState::kAssigned}};
  b.robots = {{"o1", {"R1"}}, {"o2", {"R1"}}, {"f", {"R1", "R2"}}, {"o3", {"R2"}}};
  b.plans = {{"R1", PlanOf("R1", {"o1", "o2", "f"})}, {"R2", PlanOf("R2", {"f", "o3"})}};
  return b;
}

TEST(OrderRelease, LaterOrdersGoBackForReallocationOnEveryRobotTheyShare) {
  const Book b = TwoRobots();
  const OrderRelease r = PlanRelease({"o2"}, [](const std::string&) { return OrderState::kCancelled; }, b.Lookups());
  // o2 is cancelled; f, behind it on R1, goes back, and with it o3 behind f on R2.
  EXPECT_EQ(r.to, (std::map<std::string, OrderState>{{"o2", OrderState::kCancelled},
                                                     {"f", OrderState::kAccepted},
                                                     {"o3", OrderState::kAccepted}}));
  EXPECT_EQ(r.plans.at("R1").order_ids, std::vector<std::string>{"o1"});
  EXPECT_TRUE(r.plans.at("R2").order_ids.empty());
  EXPECT_EQ(r.plans.at("R2").plan.waypoints.size(), 1u);  // the anchor
  EXPECT_EQ(r.removed.at("R1"), (std::vector<std::string>{"o2", "f"}));
  EXPECT_EQ(r.removed.at("R2"), (std::vector<std::string>{"f", "o3"}));
  // The book itself is not touched.
  EXPECT_EQ(b.plans.at("R1").order_ids.size(), 3u);
}

TEST(OrderRelease, ALostRobotsStartedOrderFailsAndTheRestIsReallocated) {
  Book b = TwoRobots();
  const OrderRelease r =
      PlanRelease(b.plans.at("R1").order_ids, [&](const std::string& id) { return StateAfterRobotLoss(b.states.at(id)); },
                  b.Lookups());
  EXPECT_EQ(r.to.at("o1"), OrderState::kFailed);
  EXPECT_EQ(r.to.at("o2"), OrderState::kAccepted);
  EXPECT_EQ(r.to.at("f"), OrderState::kAccepted);
  EXPECT_EQ(r.to.at("o3"), OrderState::kAccepted);  // behind f on R2
  EXPECT_TRUE(r.plans.at("R1").order_ids.empty());
  EXPECT_EQ(r.plans.at("R1").released_up_to, b.plans.at("R1").released_up_to);  // numbers never reused
  // A started order behind a released one fails rather than vanish.
  b.states["o3"] = OrderState::kInProgress;
  const OrderRelease again = PlanRelease({"f"}, [](const std::string&) { return OrderState::kFailed; }, b.Lookups());
  EXPECT_EQ(again.to.at("o3"), OrderState::kFailed);
}

TEST(OrderRelease, UnknownOrdersAndRobotsWithoutPlansAreSkipped) {
  Book b = TwoRobots();
  b.plans.erase("R2");
  const OrderRelease r = PlanRelease({"nope", "f"}, [](const std::string&) { return OrderState::kCancelled; }, b.Lookups());
  EXPECT_EQ(r.to.count("nope"), 0u);
  EXPECT_EQ(r.to.at("f"), OrderState::kCancelled);
  EXPECT_EQ(r.plans.count("R2"), 0u);
  EXPECT_EQ(r.plans.at("R1").order_ids, (std::vector<std::string>{"o1", "o2"}));
}

}  // namespace
}  // namespace dispatch::engine
