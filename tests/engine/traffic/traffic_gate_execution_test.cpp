// TrafficGate's plan executions (TrafficControllerConfig::execution): when a standing robot's
// next point is asked for. times: at its planned departure; claim: once its work there is
// done; order: claim, and each point passed in the plans' order (Wang2019 §3.2 steps 1-3).
// Robots here jump to a released waypoint once their planned departure has come, as the
// simulated robots leave no earlier.
#include "engine/traffic/traffic_gate.h"

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "engine/routing/route_table.h"
#include "tests/engine/traffic/controller_test_support.h"

namespace dispatch::engine {
namespace {

using testing_traffic::Grid;

class GateExecutionTest : public ::testing::Test {
 protected:
  void Start(const std::vector<std::string>& rows, PlanExecution execution) {
    map_ = Grid(rows);
    auto routes = MakeRouteTable(map_, {});
    ASSERT_TRUE(routes.ok()) << routes.error().message;
    TrafficControllerConfig c;
    c.execution = execution;
    auto gate = TrafficGate::Create(map_, std::move(routes).value(), c);
    ASSERT_TRUE(gate.ok()) << gate.error().message;
    gate_ = std::move(gate).value();
  }
  PointId P(const std::string& name) const { return *map_->FindPoint(name); }
  // A robot standing at the first of `points` at t = 0, passing the k-th at etas[k].
  void AddRobot(const std::string& id, const std::vector<std::string>& points, const std::vector<double>& etas) {
    GatePlan plan;
    for (std::size_t k = 0; k < points.size(); ++k) {
      Waypoint w;
      w.seq = static_cast<int>(k) + 1;
      w.point = P(points[k]);
      w.xy = map_->point(w.point).position;
      w.eta = etas[k];
      plan.waypoints.push_back(w);
      plan.order_of.push_back("");
    }
    plans_[id] = plan.waypoints;
    at_[id] = 0;
    gate_->Connect(id, plan.waypoints[0].xy, plan.waypoints[0].point);
    gate_->SetPlan(id, std::move(plan));
    gate_->Reached(id, 1, 0.0, plans_[id][0].xy);
    gate_->Report(id, plans_[id][0].xy, 1, 0.0);
  }
  // One 0.1 s step: the gate, then every robot that may leave its waypoint jumps to the next.
  void Step() {
    t_ += 0.1;
    for (const GateEffect& e : gate_->Step(t_)) {
      if (e.kind == GateEffect::Kind::kHold) holds_[e.robot] = e.reason;
    }
    for (auto& [id, k] : at_) {
      const auto& w = plans_[id];
      if (k + 1 >= w.size() || t_ < w[k].departure()) continue;
      if (static_cast<std::uint64_t>(w[k + 1].seq) > gate_->ReleasedUpTo(id)) continue;
      ++k;
      gate_->Reached(id, static_cast<std::uint64_t>(w[k].seq), t_, w[k].xy);
      gate_->Report(id, w[k].xy, static_cast<std::uint64_t>(w[k].seq), t_);
    }
  }
  // The time robot `id` first stood at point `name` (-1: not within `steps`).
  double ArrivalAt(const std::string& id, const std::string& name, int steps) {
    for (int i = 0; i < steps; ++i) {
      if (plans_[id][at_[id]].point == P(name)) return t_;
      Step();
    }
    return -1.0;
  }

  std::shared_ptr<const WarehouseMap> map_;
  std::unique_ptr<TrafficGate> gate_;
  std::map<std::string, std::vector<Waypoint>> plans_;
  std::map<std::string, std::size_t> at_;
  std::map<std::string, std::string> holds_;
  double t_ = 0.0;
};

// A planned wait at c1 until t = 9: under times the point ahead (c2) is asked for, and
// released, only then; under claim as soon as the robot stands at c1, and it holds c2 while it
// waits (it still leaves at 9).
TEST_F(GateExecutionTest, ClaimAsksForTheNextPointOnceTheWorkIsDoneNotAtThePlannedDeparture) {
  for (PlanExecution e : {PlanExecution::kTimes, PlanExecution::kClaim}) {
    SCOPED_TRACE(PlanExecutionName(e));
    plans_.clear();
    at_.clear();
    t_ = 0.0;
    Start({"....."}, e);
    AddRobot("A", {"c0", "c1", "c2", "c3"}, {0.0, 9.0, 10.0, 11.0});
    ASSERT_GT(ArrivalAt("A", "c1", 50), 0.0);
    while (t_ < 5.0) Step();
    EXPECT_EQ(gate_->ReleasedUpTo("A"), e == PlanExecution::kTimes ? 2u : 3u);
    const double at_c2 = ArrivalAt("A", "c2", 200);
    EXPECT_GE(at_c2, 9.0);  // the robot leaves c1 at its planned departure either way
    EXPECT_LT(at_c2, 9.5);
  }
}

// At the crossing c4, B (from the top, bound down) is planned through before A (from the left,
// bound right), and is on its way there. Under claim A, ready first, takes c4 first; under
// order it waits for B to pass, saying so, then goes.
TEST_F(GateExecutionTest, OrderPassesAPointInThePlannedOrderOfTheRobotsOnTheirWayThere) {
  for (PlanExecution e : {PlanExecution::kClaim, PlanExecution::kOrder}) {
    SCOPED_TRACE(PlanExecutionName(e));
    plans_.clear();
    at_.clear();
    holds_.clear();
    t_ = 0.0;
    Start({"@.@", "...", "@.@"}, e);
    AddRobot("A", {"c3", "c4", "c5"}, {0.0, 3.0, 4.0});
    AddRobot("B", {"c1", "c4", "c7"}, {1.0, 2.0, 3.0});
    double a_at = -1.0, b_at = -1.0;
    for (int i = 0; i < 300 && (a_at < 0 || b_at < 0); ++i) {
      Step();
      if (a_at < 0 && plans_["A"][at_["A"]].point == P("c5")) a_at = t_;
      if (b_at < 0 && plans_["B"][at_["B"]].point == P("c7")) b_at = t_;
    }
    ASSERT_GT(a_at, 0.0);
    ASSERT_GT(b_at, 0.0);
    if (e == PlanExecution::kClaim) {
      EXPECT_LT(a_at, b_at);
      EXPECT_EQ(holds_.count("A"), 0u);
    } else {
      EXPECT_GT(a_at, b_at);
      EXPECT_NE(holds_["A"].find("waiting for its turn at 'c4': B passes first"), std::string::npos) << holds_["A"];
    }
  }
}

// Under order a robot waits for its turn at most T_w1: B, planned through c4 first, is on its
// way (three points below it) but stands still (its planned departure is far off); A goes
// after T_w1 (10 s). A robot planned first that is not on its way (c4 beyond its next four
// waypoints) loses its turn at once.
TEST_F(GateExecutionTest, OrderWaitsForItsTurnAtMostTw1AndNotForARobotNotOnItsWay) {
  Start({"@.@", "...", "@.@", "@.@", "@.@", "@.@", "@.@", "@.@"}, PlanExecution::kOrder);
  AddRobot("A", {"c3", "c4", "c5"}, {0.0, 30.0, 31.0});
  AddRobot("B", {"c13", "c10", "c7", "c4", "c1"}, {25.0, 26.0, 27.0, 28.0, 29.0});
  const double a_at = ArrivalAt("A", "c4", 400);
  EXPECT_GE(a_at, 10.0);
  EXPECT_LT(a_at, 11.0);
  plans_.clear();
  at_.clear();
  t_ = 0.0;
  Start({"@.@", "...", "@.@", "@.@", "@.@", "@.@", "@.@", "@.@"}, PlanExecution::kOrder);
  AddRobot("A", {"c3", "c4", "c5"}, {0.0, 30.0, 31.0});
  // C comes up from the bottom, c4 six waypoints ahead and planned before A.
  AddRobot("C", {"c22", "c19", "c16", "c13", "c10", "c7", "c4", "c1"}, {0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0});
  EXPECT_LT(ArrivalAt("A", "c4", 400), 1.0);
}

}  // namespace
}  // namespace dispatch::engine
