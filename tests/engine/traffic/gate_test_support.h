// The TrafficGate tests' fixture: the Chu2024 floor with simulated robots that jump one
// waypoint per step as far as their release allows, robots serving single orders
// (AddRobot) and formations planned by the auction (AddFormation), a server restart
// (Restart), and the checks the tests share.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "engine/allocation/auction_allocator.h"
#include "engine/allocation/fleet_state.h"
#include "engine/fleet/formation.h"
#include "engine/map/chu2024_floor.h"
#include "engine/traffic/traffic_gate.h"

namespace dispatch::engine::testing_gate {

class TrafficGateTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto floor = BuildChu2024Floor();
    ASSERT_TRUE(floor.ok());
    map_ = std::make_shared<const WarehouseMap>(std::move(floor).value());
    auto routes = MakeRouteTable(map_, {});
    ASSERT_TRUE(routes.ok());
    routes_ = std::shared_ptr<const RouteTable>(std::move(routes).value());
    auto gate = TrafficGate::Create(map_, routes_, {});
    ASSERT_TRUE(gate.ok()) << gate.error().message;
    gate_ = std::move(gate).value();
  }
  PointId P(const std::string& name) const { return *map_->FindPoint(name); }

  struct Sim {
    std::vector<Waypoint> plan;
    std::size_t at = 0;  // index of the waypoint it stands on
    std::string order;   // the one order it serves
    std::vector<std::string> team;  // its formation's members, or empty
  };
  // Like the dispatcher's: the anchor belongs to no order, the order runs to its drop, the
  // moves after it (stepping off the drop, going home) to none.
  GatePlan GatePlanOf(const Sim& s) const {
    GatePlan g;
    g.waypoints = s.plan;
    std::size_t drop = 0;
    for (std::size_t i = 0; i < s.plan.size(); ++i) {
      if (s.plan[i].action == WaypointAction::kDrop) drop = i;
    }
    for (std::size_t i = 0; i < s.plan.size(); ++i) g.order_of.push_back(i == 0 || i > drop ? "" : s.order);
    if (!s.team.empty()) g.teams[s.order] = s.team;
    return g;
  }
  // The server restarts: a new gate; every robot reconnects where it stands and reports.
  void Restart() {
    auto gate = TrafficGate::Create(map_, routes_, {});
    ASSERT_TRUE(gate.ok()) << gate.error().message;
    gate_ = std::move(gate).value();
    for (auto& [id, s] : sims_) {
      const Waypoint& w = s.plan[s.at];
      gate_->Connect(id, w.xy, map_->NearestPoint(w.xy));
      gate_->SetPlan(id, GatePlanOf(s));
      gate_->Reached(id, static_cast<std::uint64_t>(w.seq), t_, w.xy);
      gate_->Report(id, w.xy, static_cast<std::uint64_t>(w.seq), t_);
    }
  }
  // A robot at station point `start` serving one order (picks, drop) from t = 0.
  void AddRobot(const std::string& id, const std::string& start, std::vector<std::string> picks,
                const std::string& drop, const std::string& order) {
    PlanTask task;
    for (const auto& p : picks) task.picks.push_back(P(p));
    task.drop = P(drop);
    task.work_time = 2.0;
    task.drop_time = 2.0;
    auto built = BuildPlan(*map_, *routes_, P(start), 0.0, 1.0, {task});
    ASSERT_TRUE(built.ok()) << built.error().message;
    std::vector<Waypoint> plan = built->waypoints;
    for (auto& w : plan) w.seq += 1;  // sequences start at 1
    gate_->Connect(id, map_->point(P(start)).position, P(start));
    sims_[id].plan = plan;
    sims_[id].order = order;
    gate_->SetPlan(id, GatePlanOf(sims_[id]));
    // It stands on its first waypoint: reached at once, as fleet-sim reports it.
    gate_->Reached(id, static_cast<std::uint64_t>(plan[0].seq), 0.0);
    gate_->Report(id, map_->point(P(start)).position, static_cast<std::uint64_t>(plan[0].seq), 0.0);
  }
  // Three robots at these stations carry one formation order (the auction plans them:
  // rendezvous slots, then the rigid triangle to the drop), like the dispatcher's awards.
  void AddFormation(const std::vector<std::string>& starts, const std::string& pick, const std::string& drop,
                    const std::string& order) {
    std::vector<FleetRobot> robots;
    for (std::size_t i = 0; i < starts.size(); ++i) {
      robots.push_back({"F" + std::to_string(i + 1), P(starts[i]), 0.0});
    }
    auto created = FleetState::Create(map_, routes_, robots, {});
    ASSERT_TRUE(created.ok()) << created.error().message;
    FleetState fleet = std::move(created).value();
    Order o;
    o.id = order;
    o.picks = {P(pick)};
    o.drop = P(drop);
    o.formation = true;
    o.work_time = 2.0;
    AuctionAllocator auction;
    auto award = auction.Allocate(o, fleet);
    ASSERT_TRUE(award.ok()) << award.error().message;
    ASSERT_EQ(award->winners.size(), 3u);
    for (const auto& id : award->winners) {
      std::vector<Waypoint> plan = fleet.plan(*fleet.FindRobot(id)).waypoints;
      for (auto& w : plan) w.seq += 1;
      const PointId start = plan.front().point;
      gate_->Connect(id, map_->point(start).position, start);
      sims_[id].plan = plan;
      sims_[id].order = order;
      sims_[id].team = award->winners;
      gate_->SetPlan(id, GatePlanOf(sims_[id]));
    }
    for (const auto& id : award->winners) {
      const Waypoint& w = sims_[id].plan.front();
      gate_->Reached(id, static_cast<std::uint64_t>(w.seq), 0.0);
      gate_->Report(id, w.xy, static_cast<std::uint64_t>(w.seq), 0.0);
    }
    team_ = award->winners;
  }
  // Steps until every robot stands on its plan's last waypoint (or `until` holds); false after
  // `max_steps`. `observe` runs after every step. `released` runs between the gate's step and
  // the robots' moves (they arrive in the step they are released), and stops the run when it
  // returns true.
  bool Run(int max_steps, const std::function<void(double)>& observe = {},
           const std::function<bool()>& until = {}, const std::function<bool()>& released = {}) {
    double& t = t_;
    for (int step = 0; step < max_steps; ++step) {
      t += 0.1;
      for (GateEffect& e : gate_->Step(t)) {
        if (e.kind == GateEffect::Kind::kRewrite) sims_[e.robot].plan = e.waypoints;
        if (e.kind == GateEffect::Kind::kRelease) ++releases_;
        if (e.kind == GateEffect::Kind::kBlocked) ADD_FAILURE() << e.robot << " blocked: " << e.reason;
      }
      if (released && released()) return true;
      bool done = true;
      for (auto& [id, s] : sims_) {
        // Re-find where it stands in a rewritten plan (by position among the sequences).
        const std::uint64_t released = gate_->ReleasedUpTo(id);
        if (s.at + 1 < s.plan.size()) done = false;
        if (s.at + 1 >= s.plan.size()) continue;
        const Waypoint& here = s.plan[s.at];
        const Waypoint& next = s.plan[s.at + 1];
        if (static_cast<std::uint64_t>(next.seq) > released || t < here.departure()) continue;
        ++s.at;
        gate_->Reached(id, static_cast<std::uint64_t>(next.seq), t, next.xy);
        // State reports come every `report_every_` steps, staggered by robot (like fleet-sim's
        // groups); the arrival carries the pose in between.
        if ((step + static_cast<int>(std::hash<std::string>{}(id) % 97)) % report_every_ == 0) {
          gate_->Report(id, next.xy, static_cast<std::uint64_t>(next.seq), t);
        }
      }
      gate_->SampleDistances(t);
      if (observe) observe(t);
      if (done || (until && until())) return true;
    }
    return false;
  }

  std::shared_ptr<const WarehouseMap> map_;
  std::shared_ptr<const RouteTable> routes_;
  std::unique_ptr<TrafficGate> gate_;
  std::map<std::string, Sim> sims_;
  int releases_ = 0;
  int report_every_ = 1;
  // Every robot's traffic state, for a failure's message.
  std::string DescribeAll() const {
    std::string out;
    for (const auto& [id, sim] : sims_) out += gate_->Describe(id) + "\n";
    return out;
  }
  // How many waypoints the robot stands past its plan's first pick (negative: before it).
  long PastPick(const std::string& id) {
    const Sim& s = sims_[id];
    std::size_t pick = 0;
    while (pick < s.plan.size() && s.plan[pick].action != WaypointAction::kPick) ++pick;
    return static_cast<long>(s.at) - static_cast<long>(pick);
  }
  // No two robots of different agents came closer than eps1.
  void ExpectEps1Kept() const {
    const MinDistance& d = gate_->min_distance();
    EXPECT_GE(d.distance, 0.6 - 1e-9) << d.a << " and " << d.b << " at t = " << d.time;
  }

  // Runs a formation order until it has moved 3 points past its pick, restarts the gate (one
  // member a point behind the others if `one_behind`), and runs everything to the end.
  void RestartWhileMoving(bool one_behind);
  double t_ = 0.0;  // the simulated time
  std::vector<std::string> team_;  // AddFormation's members, leader first
};

}  // namespace dispatch::engine::testing_gate
