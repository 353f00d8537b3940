// TrafficGate on the Chu2024 floor with simulated robots that jump one waypoint per step as
// far as their release allows: every plan is driven to its end, releases come point by point,
// and robots of different agents are never given points closer than eps1.
#include "engine/traffic/traffic_gate.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <map>
#include <set>

#include "engine/allocation/auction_allocator.h"
#include "engine/allocation/fleet_state.h"
#include "engine/fleet/formation.h"
#include "engine/map/chu2024_floor.h"

namespace dispatch::engine {
namespace {

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
  // `max_steps`. `observe` runs after every step.
  bool Run(int max_steps, const std::function<void(double)>& observe = {},
           const std::function<bool()>& until = {}) {
    double& t = t_;
    for (int step = 0; step < max_steps; ++step) {
      t += 0.1;
      for (GateEffect& e : gate_->Step(t)) {
        if (e.kind == GateEffect::Kind::kRewrite) sims_[e.robot].plan = e.waypoints;
        if (e.kind == GateEffect::Kind::kRelease) ++releases_;
        if (e.kind == GateEffect::Kind::kBlocked) ADD_FAILURE() << e.robot << " blocked: " << e.reason;
      }
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

TEST_F(TrafficGateTest, ARobotIsReleasedPointByPointToTheEndOfItsPlan) {
  AddRobot("R1", "park-P1", {"K3-2-3N"}, "D-B2", "o1");
  EXPECT_LT(gate_->ReleasedUpTo("R1"), static_cast<std::uint64_t>(sims_["R1"].plan.back().seq));
  ASSERT_TRUE(Run(5000)) << gate_->Describe("R1");
  EXPECT_GE(releases_, static_cast<int>(sims_["R1"].plan.size()) / 2);
  EXPECT_GT(gate_->stats().grants, 0u);
}

// Issue 18 §4: a paused robot stops where its releases end and is held, saying who paused
// it; resumed, it drives its plan to the end.
TEST_F(TrafficGateTest, APausedRobotIsHeldWhereItsReleasesEndUntilResumed) {
  AddRobot("R1", "park-P1", {"K3-2-3N"}, "D-B2", "o1");
  ASSERT_TRUE(Run(20, {}, [&] { return sims_["R1"].at >= 2; })) << gate_->Describe("R1");
  ASSERT_TRUE(gate_->SetPaused("R1", "op-1"));
  EXPECT_TRUE(gate_->Paused("R1"));
  EXPECT_FALSE(gate_->SetPaused("", "op-1"));
  std::string hold;
  const std::uint64_t released = gate_->ReleasedUpTo("R1");
  for (int i = 0; i < 300; ++i) {  // 30 s: it would have driven on long since
    t_ += 0.1;
    for (const GateEffect& e : gate_->Step(t_)) {
      if (e.robot == "R1" && e.kind == GateEffect::Kind::kHold) hold = e.reason;
      EXPECT_NE(e.kind, GateEffect::Kind::kRelease) << "released while paused";
    }
    Sim& s = sims_["R1"];
    if (s.at + 1 < s.plan.size() && static_cast<std::uint64_t>(s.plan[s.at + 1].seq) <= released) {
      ++s.at;
      gate_->Reached("R1", static_cast<std::uint64_t>(s.plan[s.at].seq), t_, s.plan[s.at].xy);
    }
  }
  EXPECT_EQ(hold, "paused by op-1");
  EXPECT_EQ(gate_->RobotState("R1").paused_by, "op-1");
  EXPECT_EQ(gate_->ReleasedUpTo("R1"), released);
  EXPECT_LT(sims_["R1"].at + 1, sims_["R1"].plan.size());
  ASSERT_TRUE(gate_->SetPaused("R1", ""));
  ASSERT_TRUE(Run(5000)) << gate_->Describe("R1");
  EXPECT_EQ(gate_->RobotState("R1").paused_by, "");
}

// Issue 18 §3-4: an offline robot is an obstacle where it stands (a ghost at R1's drop keeps
// R1 from finishing) until an operator clears it off the floor; connected again, it is placed
// where it then stands.
TEST_F(TrafficGateTest, AClearedOfflineRobotIsNoObstacleUntilItConnectsAgain) {
  gate_->Connect("G", map_->point(P("D-B2")).position, P("D-B2"));
  gate_->Disconnect("G");
  AddRobot("R1", "park-P1", {"K3-2-3N"}, "D-B2", "o1");
  EXPECT_FALSE(Run(600)) << "R1 reached a drop a robot stands on";  // 60 s, below blocked_after
  EXPECT_FALSE(gate_->Remove("R9"));  // unknown
  EXPECT_FALSE(gate_->Remove("R1"));  // connected: not cleared
  ASSERT_TRUE(gate_->Remove("G"));
  ASSERT_TRUE(Run(5000)) << gate_->Describe("R1");
  EXPECT_EQ(sims_["R1"].plan[sims_["R1"].at].point, P("D-B2"));
  // Back: it stands where it connects, and a robot sent there waits for it again.
  gate_->Connect("G", map_->point(P("K3-2-3N")).position, P("K3-2-3N"));
  AddRobot("R2", "park-P2", {"K3-2-3N"}, "D-B2", "o2");
  EXPECT_FALSE(Run(600)) << "R2 reached a pick a robot stands on";
}

TEST_F(TrafficGateTest, RobotsSharingPickAndDropKeepEps1) {
  // Both serve the same pick and drop: they must take turns there.
  AddRobot("R1", "park-P1", {"K3-2-3N"}, "D-B2", "o1");
  AddRobot("R2", "park-P2", {"K3-2-3N"}, "D-B2", "o2");
  AddRobot("R3", "park-P3", {"K3-2-2N"}, "D-B2", "o3");
  ASSERT_TRUE(Run(20000)) << DescribeAll();
  ExpectEps1Kept();
}

TEST_F(TrafficGateTest, ARobotIsSeenWhereItLastArrivedNotWhereItLastReported) {
  AddRobot("R1", "park-P1", {"K3-2-3N"}, "D-B2", "o1");
  AddRobot("R2", "park-P2", {"K3-2-2N"}, "D-B1", "o2");
  const auto& plan = sims_["R1"].plan;
  std::size_t i = 1;
  while (i < plan.size() && (plan[i].xy - plan[0].xy).norm() < 1.0) ++i;
  ASSERT_LT(i, plan.size());
  // R2's latest report is 0.3 m from R1's latest report, but R1 has arrived elsewhere since.
  const Eigen::Vector2d r2 = plan[0].xy + Eigen::Vector2d(0.3, 0.0);
  gate_->Report("R2", r2, static_cast<std::uint64_t>(sims_["R2"].plan[0].seq), 0.1);
  gate_->Reached("R1", static_cast<std::uint64_t>(plan[i].seq), 0.1, plan[i].xy);
  gate_->SampleDistances(0.1);
  // Not closer than they are (pairs farther apart than the sample's grid are not measured).
  EXPECT_GE(gate_->min_distance().distance, (plan[i].xy - r2).norm() - 1e-9);
}

TEST_F(TrafficGateTest, RobotsFollowingEachOtherKeepEps1BetweenSparseReports) {
  // One route for three robots; positions are reported every 7th step only, so most of what
  // the gate knows comes from arrivals. (Pairing a stale report of the robot ahead with a
  // fresh one of the robot behind read as a 0.566 m approach in the service.)
  report_every_ = 7;
  AddRobot("R1", "park-P1", {"K3-2-3N"}, "D-B2", "o1");
  AddRobot("R2", "park-P2", {"K3-2-3N"}, "D-B2", "o2");
  AddRobot("R3", "park-P3", {"K3-2-3N"}, "D-B2", "o3");
  ASSERT_TRUE(Run(20000)) << DescribeAll();
  ExpectEps1Kept();
}

TEST_F(TrafficGateTest, AFormationMovesAsOneAgentAndHoldsItsGrantsTogether) {
  // Chu2024 §3.2 through the gate: the members meet at the pick, cross the floor as one agent
  // (one grant for the three of them), split after the drop; a solo robot crossing the same
  // aisles keeps eps2 from the formation (the gate's distance counts agents, not members).
  AddFormation({"park-P1", "park-P2", "park-P3"}, "K3-2-3N", "D-B2", "f1");
  AddRobot("R4", "park-P4", {"K3-2-2N"}, "D-B1", "o4");
  bool all_in_team = false, shared_grant = false;
  std::set<std::string> seen_formation;
  ASSERT_TRUE(Run(40000, [&](double) {
    int in_team = 0;
    for (const auto& id : team_) {
      if (gate_->RobotState(id).formation == "f1") {
        ++in_team;
        seen_formation.insert(id);
      }
    }
    all_in_team = all_in_team || in_team == 3;
    for (const GateIntersection& i : gate_->Intersections()) {
      const std::set<std::string> holders(i.holders.begin(), i.holders.end());
      if (holders.count(team_[0]) && holders.count(team_[1]) && holders.count(team_[2])) shared_grant = true;
      // Nobody else holds an intersection the formation holds.
      if (holders.count(team_[0])) {
        EXPECT_EQ(holders.count("R4"), 0u);
      }
    }
  })) << DescribeAll();
  EXPECT_TRUE(all_in_team);
  EXPECT_TRUE(shared_grant);
  EXPECT_EQ(seen_formation.size(), 3u);
  for (const auto& id : team_) EXPECT_EQ(gate_->RobotState(id).formation, "") << id;  // dissolved
  ExpectEps1Kept();
}

// A member on its way to its rendezvous, not in its team yet, drives to a point beside a
// teammate (exempt from it as a teammate) when its order is given back (it was blocked, say):
// it arrives there all the same, so it stays exempt from that team's members until it has
// driven off, as a member standing beside one does. Found through the service (the burst
// three at a time): such a member arrived a stranger 0.400 m from a teammate.
TEST_F(TrafficGateTest, AMemberDrivingUpToATeammateWhenItsOrderGoesKeepsItsExemption) {
  AddFormation({"park-P1", "park-P2", "park-P3"}, "K3-2-3N", "D-B2", "f1");
  const double envelope = 0.6 + 0.4 / std::sqrt(3.0);
  std::string member;
  // The fixture's robots arrive in the step they are released: look between the gate's step
  // and the robots' moves, while a member drives.
  for (int step = 0; step < 40000 && member.empty(); ++step) {
    t_ += 0.1;
    for (GateEffect& e : gate_->Step(t_)) {
      if (e.kind == GateEffect::Kind::kRewrite) sims_[e.robot].plan = e.waypoints;
    }
    for (const auto& id : team_) {
      const Sim& s = sims_[id];
      if (gate_->RobotState(id).formation == "f1" || s.at + 1 >= s.plan.size()) continue;
      const Waypoint& next = s.plan[s.at + 1];
      if (static_cast<std::uint64_t>(next.seq) > gate_->ReleasedUpTo(id)) continue;  // not driving on
      for (const auto& other : team_) {
        const Sim& o = sims_[other];
        if (other != id && (o.plan[o.at].xy - next.xy).norm() < envelope - 1e-9 &&
            (o.plan[o.at].xy - s.plan[s.at].xy).norm() >= envelope) {
          member = id;
        }
      }
    }
    if (!member.empty()) break;
    for (auto& [id, s] : sims_) {
      if (s.at + 1 >= s.plan.size()) continue;
      const Waypoint& next = s.plan[s.at + 1];
      if (static_cast<std::uint64_t>(next.seq) > gate_->ReleasedUpTo(id) || t_ < s.plan[s.at].departure()) continue;
      ++s.at;
      gate_->Reached(id, static_cast<std::uint64_t>(next.seq), t_, next.xy);
      gate_->Report(id, next.xy, static_cast<std::uint64_t>(next.seq), t_);
    }
  }
  ASSERT_FALSE(member.empty()) << "no member drove up to a teammate\n" << DescribeAll();
  // Its order goes: its plan is the waypoint it stands on (it drives on to the one released).
  Sim& m = sims_[member];
  Sim alone;
  alone.plan = {m.plan[m.at], m.plan[m.at + 1]};
  gate_->SetPlan(member, GatePlanOf(alone));
  const GateRobotState state = gate_->RobotState(member);
  EXPECT_NE(std::find(state.teams.begin(), state.teams.end(), "f1"), state.teams.end()) << gate_->Describe(member);
}

TEST_F(TrafficGateTest, AnAssemblingFormationWaitsOnItsMissingMembersInTheControllersGraph) {
  // The team's agent holds the rendezvous while members are still on their way: the controller
  // must see that wait, or a robot holding a member up while it waits for the team's point is a
  // cycle nobody breaks (the service froze so with formations, issue 15).
  AddFormation({"park-P1", "park-P2", "park-P3"}, "K3-2-3N", "D-B2", "f1");
  std::string joined, describe;
  ASSERT_TRUE(Run(40000, {}, [&] {
    int in_team = 0;
    for (const auto& id : team_) {
      if (gate_->RobotState(id).formation == "f1") {
        ++in_team;
        joined = id;
      }
    }
    if (in_team > 0 && in_team < 3) describe = gate_->Describe(joined);
    return in_team == 3;
  })) << DescribeAll();
  ASSERT_FALSE(describe.empty()) << "the members all joined at once";
  EXPECT_NE(describe.find("waiting on"), std::string::npos) << describe;
  EXPECT_NE(describe.find("(formation f1 waits for F"), std::string::npos) << describe;
  ASSERT_TRUE(Run(40000)) << DescribeAll();  // and it still completes
  ExpectEps1Kept();
}

TEST_F(TrafficGateTest, AFormationMovingWhenTheServerRestartsIsFormedAgainWhereItIs) { RestartWhileMoving(false); }

TEST_F(TrafficGateTest, AFormationAPointApartInLockstepIsFormedAgainDrivingOn) { RestartWhileMoving(true); }

void TrafficGateTest::RestartWhileMoving(bool one_behind) {
  // The gate's teams live in memory only: after a restart the members must not go on as three
  // single robots (their slots are D_f off the points the controller keeps apart).
  AddFormation({"park-P1", "park-P2", "park-P3"}, "K3-2-3N", "D-B2", "f1");
  AddRobot("R4", "park-P4", {"K3-2-2N"}, "D-B1", "o4");
  ASSERT_TRUE(Run(40000, {}, [&] {
    for (const auto& id : team_) {
      if (PastPick(id) < 3) return false;
    }
    return true;
  }));
  for (const auto& id : team_) ASSERT_LT(sims_[id].at + 1, sims_[id].plan.size()) << id << " is done already";
  // One member's last arrival not reported yet: it still drives to the point the others are at.
  if (one_behind) --sims_[team_[1]].at;
  Restart();
  bool formed_again = false;
  ASSERT_TRUE(Run(40000, [&](double) {
    int in_team = 0;
    for (const auto& id : team_) in_team += gate_->RobotState(id).formation == "f1";
    formed_again = formed_again || in_team == 3;
  })) << DescribeAll();
  EXPECT_TRUE(formed_again);
  ExpectEps1Kept();
  const std::vector<std::string> notes = gate_->TakeNotes();
  const bool drove_on = std::any_of(notes.begin(), notes.end(), [](const std::string& n) {
    return n.find("formed again") != std::string::npos && n.find("driving on") != std::string::npos;
  });
  EXPECT_EQ(drove_on, one_behind);
}

TEST_F(TrafficGateTest, AFormationOrderCompletesWhateverMomentTheServerRestartsAt) {
  // Approaching, assembling, moving, at the drop, leaving it: the restart comes at one of 60
  // moments until the team has dissolved, then at 20 more until every robot has finished (idle
  // robots stepping off the drops, seen by the new gate away from their stations).
  auto start = [&] {
    AddFormation({"park-P1", "park-P2", "park-P3"}, "K3-2-3N", "D-B2", "f1");
    AddRobot("R4", "park-P4", {"K3-2-2N"}, "D-B1", "o4");
  };
  start();
  int steps = 0, dissolved = -1;
  bool formed = false;
  ASSERT_TRUE(Run(40000, [&](double) {
    ++steps;
    const bool in_team = gate_->RobotState(team_[0]).formation == "f1";
    formed = formed || in_team;
    if (formed && !in_team && dissolved < 0) dissolved = steps;
  }));
  ASSERT_GT(dissolved, 0);
  int formed_again = 0, left_alone = 0;  // which way the gate took
  for (int cut = 1; cut <= 80; ++cut) {
    const int at = cut <= 60 ? cut * dissolved / 60 : dissolved + (cut - 60) * (steps - dissolved) / 21;
    SCOPED_TRACE("restart at step " + std::to_string(at) + " of " + std::to_string(steps));
    sims_.clear();
    t_ = 0.0;
    SetUp();
    start();
    int step = 0;
    ASSERT_TRUE(Run(40000, {}, [&] { return ++step >= at; }));
    Restart();
    ASSERT_TRUE(Run(40000)) << DescribeAll();
    ExpectEps1Kept();
    for (const std::string& note : gate_->TakeNotes()) {
      formed_again += note.find("formed again") != std::string::npos;
      left_alone += note.find("was leaving its drop") != std::string::npos;
    }
  }
  EXPECT_GT(formed_again, 0);
  EXPECT_GT(left_alone, 0);
  std::cout << formed_again << " restarts formed the team again, " << left_alone << " found it leaving its drop\n";
}

TEST_F(TrafficGateTest, RegressionABlockedFormationMemberIsNeverPlacedAtItsHome) {
  // Issue 15 §3b: a moving formation is blocked; the dispatcher takes the order away, which cuts
  // each member's plan back to its anchor (its parking point). The members still stand in their
  // slots and must stay obstacles there: the gate used to put them back at home, and a robot
  // then came D_f = 0.231 m (later 0 m) from one of them. Now the team's agent keeps the point
  // while the members leave it one at a time for a free point next to it (DissolveTeam), each
  // driving there, never home.
  AddFormation({"park-P1", "park-P2", "park-P3"}, "K3-2-3N", "D-B2", "f1");
  ASSERT_TRUE(Run(40000, {}, [&] {
    for (const auto& id : team_) {
      if (gate_->RobotState(id).formation != "f1" || PastPick(id) < 3) return false;
    }
    return true;
  })) << DescribeAll();
  std::map<std::string, Eigen::Vector2d> stands;
  std::map<std::string, PointId> home;
  for (const auto& id : team_) {
    Sim& s = sims_[id];
    ASSERT_LT(s.at + 1, s.plan.size()) << id << " is done already";
    stands[id] = s.plan[s.at].xy;
    home[id] = s.plan.front().point;
    gate_->Report(id, stands[id], static_cast<std::uint64_t>(s.plan[s.at].seq), t_);
  }
  for (const auto& id : team_) {  // the dispatcher's kBlocked -> ReleaseOrders -> SyncGate
    Sim& s = sims_[id];
    s.plan.resize(1);  // the anchor only: the simulated robot stays in its slot
    s.at = 0;
    GatePlan cut;
    cut.waypoints = s.plan;
    cut.order_of = {""};
    gate_->SetPlan(id, cut);
  }
  auto all_left = [&] {
    for (const auto& id : team_) {
      if (gate_->RobotState(id).formation != "") return false;
    }
    return true;
  };
  // Where the gate puts each member back on the floor, the step it leaves the team. From then on
  // it is released point by point like any robot: never more than the next point's waypoints
  // ahead.
  std::map<std::string, PointId> placed;
  for (int step = 0; step < 2000 && !all_left(); ++step) {
    Run(1);
    for (const auto& id : team_) {
      if (!gate_->RobotState(id).formation.empty()) continue;
      if (!placed.count(id)) placed[id] = gate_->StartPoint(id);
      const Sim& s = sims_[id];
      std::set<PointId> ahead;
      for (std::size_t k = s.at + 1; k < s.plan.size() && static_cast<std::uint64_t>(s.plan[k].seq) <= gate_->ReleasedUpTo(id); ++k) {
        if (s.plan[k].point != s.plan[s.at].point) ahead.insert(s.plan[k].point);
      }
      ASSERT_LE(ahead.size(), 1u) << gate_->Describe(id);
    }
  }
  ASSERT_TRUE(all_left()) << DescribeAll();
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (const auto& [id, xy] : stands) centre += xy / static_cast<double>(stands.size());
  const PointId team_point = map_->NearestPoint(centre);
  // On the team's point or next to it (an idle member of a broken-up team drives on home from
  // there, as it should), never at its home.
  int on_floor = 0;
  for (const auto& id : team_) {
    const PointId at = placed[id];
    if (at == kNoPoint) continue;  // still in its slot (no way off in time): a stray, seen standing
    ++on_floor;
    EXPECT_NE(at, home[id]) << gate_->Describe(id);
    EXPECT_TRUE(at == team_point || map_->FindArc(team_point, at).has_value()) << gate_->Describe(id);
  }
  EXPECT_GE(on_floor, 2) << DescribeAll();
  // A robot sent the formation's way keeps eps1 from the members standing in their slots.
  AddRobot("R4", "park-P4", {"K3-2-3N"}, "D-B2", "o4");
  Run(600, {}, [&] { return sims_["R4"].at + 1 >= sims_["R4"].plan.size(); });
  ExpectEps1Kept();
}

}  // namespace
}  // namespace dispatch::engine
