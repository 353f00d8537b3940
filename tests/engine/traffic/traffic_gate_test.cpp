// TrafficGate on the Chu2024 floor (gate_test_support.h): robots serving single orders are
// released point by point to the end of their plans, paused, cleared off the floor, and never
// given points closer than eps1. Formations are in traffic_gate_formation_test.cpp.
#include "engine/traffic/traffic_gate.h"

#include <gtest/gtest.h>

#include "tests/engine/traffic/gate_test_support.h"

namespace dispatch::engine {
namespace {

using testing_gate::TrafficGateTest;

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

}  // namespace
}  // namespace dispatch::engine
