#include "clients/sim_robot.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace dispatch::clients {
namespace {

v1::TimedWaypoint Wp(std::uint64_t seq, double x, double y, double eta,
                     v1::WaypointAction action = v1::WAYPOINT_ACTION_MOVE, double dwell = 0,
                     bool released = true, const std::string& order = "") {
  v1::TimedWaypoint w;
  w.set_sequence(seq);
  w.set_point_id(static_cast<int>(seq));
  w.set_x(x);
  w.set_y(y);
  w.set_eta(eta);
  w.set_action(action);
  w.set_dwell(dwell);
  w.set_released(released);
  w.set_order_id(order);
  return w;
}

// Start (0,0) -> (2,0) -> pick at (4,0), 3 s -> drop at (4,3), 1 s; all released, v = 1 m/s.
v1::ServerMessage Plan(std::uint64_t seq, bool release_all = true) {
  v1::ServerMessage m;
  m.set_sequence(seq);
  v1::Assignment* a = m.mutable_assignment();
  a->set_plan_id(1);
  a->add_order_ids("o1");
  *a->add_waypoints() = Wp(1, 0, 0, 0);
  *a->add_waypoints() = Wp(2, 2, 0, 2);
  *a->add_waypoints() = Wp(3, 4, 0, 4, v1::WAYPOINT_ACTION_PICK, 3, release_all, "o1");
  *a->add_waypoints() = Wp(4, 4, 3, 10, v1::WAYPOINT_ACTION_DROP, 1, release_all, "o1");
  a->set_released_up_to_sequence(release_all ? 4 : 2);
  return m;
}

struct Events {
  std::vector<v1::RobotMessage> events;
  std::vector<std::string> Names() const {
    std::vector<std::string> n;
    for (const auto& e : events) {
      if (e.has_waypoint_reached()) n.push_back("wp" + std::to_string(e.waypoint_reached().sequence()));
      if (e.has_task_event()) {
        n.push_back(e.task_event().type() == v1::TASK_EVENT_TYPE_PICKED ? "picked" : "dropped");
      }
    }
    return n;
  }
};

void StepTo(SimRobot& r, double from, double to, double dt, Events& run) {
  for (double t = from; t <= to + 1e-9; t += dt) r.Step(t, run.events);
}

TEST(SimRobotTest, FollowsTheTimedPlanAndReportsInOrder) {
  SimRobot r("R1", {0, 0}, 1.0);
  ASSERT_TRUE(r.Apply(Plan(1)));
  Events run;
  StepTo(r, 0.0, 3.0, 0.1, run);
  EXPECT_NEAR(r.position().x(), 3.0, 1e-6);  // 1 m/s along x
  StepTo(r, 3.1, 6.9, 0.1, run);
  EXPECT_NEAR(r.position().x(), 4.0, 1e-9);  // picking (arrived at 4 s, 3 s of work)
  EXPECT_EQ(run.Names(), (std::vector<std::string>{"wp1", "wp2", "wp3"}));
  EXPECT_EQ(r.Report().state_report().state(), v1::ROBOT_STATE_WORKING);
  StepTo(r, 7.0, 9.9, 0.1, run);
  // Picked at 7 s; the drop point (3 m on) is reached at 10 s, its eta.
  EXPECT_EQ(run.Names(), (std::vector<std::string>{"wp1", "wp2", "wp3", "picked"}));
  EXPECT_NEAR(r.position().y(), 2.9, 1e-6);
  StepTo(r, 10.05, 12.0, 0.1, run);
  EXPECT_EQ(run.Names(),
            (std::vector<std::string>{"wp1", "wp2", "wp3", "picked", "wp4", "dropped"}));
  EXPECT_TRUE(r.idle());
  EXPECT_EQ(r.Report().state_report().state(), v1::ROBOT_STATE_IDLE);
  EXPECT_EQ(r.Report().state_report().last_waypoint_sequence(), 4u);
}

// With 1 s per 90 degrees the robot turns in place before the leg up to the drop (the first
// leg, from standing, turns nothing): it reaches the drop 1 s later than without turning.
TEST(SimRobotTest, TurnsInPlaceBeforeANewHeading) {
  double reached_drop[2] = {0, 0};
  for (int turning = 0; turning < 2; ++turning) {
    SimRobot r("R1", {0, 0}, 1.0);
    r.set_turn_time(turning);
    ASSERT_TRUE(r.Apply(Plan(1)));
    Events run;
    for (double t = 0; t <= 20 + 1e-9; t += 0.05) {
      const std::size_t before = run.events.size();
      r.Step(t, run.events);
      for (std::size_t k = before; k < run.events.size(); ++k) {
        if (run.events[k].has_waypoint_reached() && run.events[k].waypoint_reached().sequence() == 4 &&
            reached_drop[turning] == 0) {
          reached_drop[turning] = t;
        }
      }
    }
    EXPECT_EQ(run.Names(), (std::vector<std::string>{"wp1", "wp2", "wp3", "picked", "wp4", "dropped"}));
  }
  // Without turning: 4 m, 3 s pick, 3 m -> at the drop by 10 s (its planned eta). With it,
  // the 90-degree turn after the pick adds 1 s.
  EXPECT_NEAR(reached_drop[1] - reached_drop[0], 1.0, 0.1);
}

// A four-wheel-steer plan in a free space: east 2 m facing east, crab 1 m north still facing
// east, spin to face north, then an arc-like leg turning back east. No turn in place before a
// leg (turn_time is for lanes); the heading is the plan's, not the direction of travel.
TEST(SimRobotTest, DrivesTheFourWheelSteerModesWithThePlannedHeadings) {
  SimRobot r("R1", {0, 0}, 1.0);
  r.set_turn_time(1.0);
  v1::ServerMessage m;
  m.set_sequence(1);
  v1::Assignment* a = m.mutable_assignment();
  a->set_plan_id(1);
  auto posed = [&](std::uint64_t seq, double x, double y, double eta, double heading, v1::MotionMode mode) {
    v1::TimedWaypoint w = Wp(seq, x, y, eta);
    w.set_heading(heading);
    w.set_motion_mode(mode);
    *a->add_waypoints() = w;
  };
  posed(1, 0, 0, 0, 0.0, v1::MOTION_MODE_UNSPECIFIED);
  posed(2, 2, 0, 2, 0.0, v1::MOTION_MODE_FORWARD);
  posed(3, 2, 1, 3, 0.0, v1::MOTION_MODE_CRAB_LEFT);
  posed(4, 2, 1, 4.6, std::numbers::pi / 2, v1::MOTION_MODE_SPIN_LEFT);
  posed(5, 3, 2, 6.2, 0.0, v1::MOTION_MODE_ARC_FORWARD_RIGHT);
  a->set_released_up_to_sequence(5);
  ASSERT_TRUE(r.Apply(m));
  Events run;
  double crab_heading_max = 0.0, arc_mid_heading = -1.0;
  for (double t = 0; t <= 8 + 1e-9; t += 0.05) {
    r.Step(t, run.events);
    if (r.position().x() > 1.99 && r.position().x() < 2.01 && r.position().y() > 0.2 && r.position().y() < 0.8) {
      crab_heading_max = std::max(crab_heading_max, std::abs(r.heading()));
    }
    const double along = (r.position() - Eigen::Vector2d(2, 1)).norm() / std::sqrt(2.0);
    if (r.position().x() > 2.01 && along > 0.45 && along < 0.55) arc_mid_heading = r.heading();
  }
  EXPECT_EQ(run.Names(), (std::vector<std::string>{"wp1", "wp2", "wp3", "wp4", "wp5"}));
  EXPECT_LT(crab_heading_max, 1e-9) << "a crab keeps the heading";
  EXPECT_NEAR(arc_mid_heading, std::numbers::pi / 4, 0.1) << "an arc turns evenly";
  EXPECT_NEAR(r.heading(), 0.0, 1e-9);
  EXPECT_TRUE(r.position().isApprox(Eigen::Vector2d(3, 2)));
  // The spin's pose was reported at its waypoint, facing north.
  for (const auto& e : run.events) {
    if (e.has_waypoint_reached() && e.waypoint_reached().sequence() == 4) {
      EXPECT_NEAR(e.waypoint_reached().pose().theta(), std::numbers::pi / 2, 1e-9);
    }
    if (e.has_waypoint_reached() && e.waypoint_reached().sequence() == 3) {
      EXPECT_NEAR(e.waypoint_reached().pose().theta(), 0.0, 1e-9);
    }
  }
}

TEST(SimRobotTest, WaitsForPlannedDepartureWhenAhead) {
  SimRobot r("R1", {0, 0}, 1.0);
  v1::ServerMessage m = Plan(1);
  m.mutable_assignment()->mutable_waypoints(0)->set_eta(5.0);  // leave the start at 5 s
  r.Apply(m);
  Events run;
  StepTo(r, 0.0, 4.9, 0.1, run);
  EXPECT_EQ(r.position().x(), 0.0);
  StepTo(r, 5.0, 6.0, 0.1, run);
  EXPECT_NEAR(r.position().x(), 1.0, 1e-6);
}

TEST(SimRobotTest, StopsAtTheReleaseHorizonUntilAGrant) {
  SimRobot r("R1", {0, 0}, 1.0);
  r.Apply(Plan(1, /*release_all=*/false));
  Events run;
  StepTo(r, 0.0, 20.0, 0.5, run);
  EXPECT_EQ(r.position().x(), 2.0);  // waypoint 2 is the last released one
  EXPECT_EQ(run.Names(), (std::vector<std::string>{"wp1", "wp2"}));
  EXPECT_EQ(r.Report().state_report().state(), v1::ROBOT_STATE_WAITING);
  v1::ServerMessage g;
  g.set_sequence(2);
  g.mutable_grant()->set_release_up_to_sequence(4);
  r.Apply(g);
  StepTo(r, 20.5, 21.0, 0.5, run);
  EXPECT_NEAR(r.position().x(), 3.0, 1e-9);
}

TEST(SimRobotTest, MeasuresHowLongItStoodReadyForARelease) {
  SimRobot r("R1", {0, 0}, 1.0);
  r.Apply(Plan(1, /*release_all=*/false));
  Events run;
  StepTo(r, 0.0, 1.5, 0.5, run);
  EXPECT_FALSE(r.waiting_for_release_since());  // still driving to waypoint 2
  StepTo(r, 2.0, 3.0, 0.5, run);  // reports waypoint 2 in the step at t = 2
  ASSERT_TRUE(r.waiting_for_release_since());
  EXPECT_DOUBLE_EQ(*r.waiting_for_release_since(), 2.0);
  v1::ServerMessage g;
  g.set_sequence(2);
  g.mutable_grant()->set_release_up_to_sequence(3);
  std::optional<double> waited;
  r.Apply(g, 3.25, &waited);
  ASSERT_TRUE(waited);
  EXPECT_DOUBLE_EQ(*waited, 1.25);
  EXPECT_FALSE(r.waiting_for_release_since());
  // At the pick: it drove on from t = 3 (released mid-step), arrived at 5, worked 3 s; ready
  // from the later of its work's end (8) and the planned departure (4 + 3 = 7).
  StepTo(r, 3.5, 7.5, 0.5, run);
  EXPECT_FALSE(r.waiting_for_release_since());  // still working
  StepTo(r, 8.0, 8.0, 0.5, run);
  ASSERT_TRUE(r.waiting_for_release_since());
  EXPECT_DOUBLE_EQ(*r.waiting_for_release_since(), 8.0);
  // A Hold makes it a traffic wait: the Resume that follows measures nothing.
  v1::ServerMessage h;
  h.set_sequence(3);
  h.mutable_hold()->set_reason("point held");
  r.Apply(h, 8.0, &waited);
  EXPECT_FALSE(r.waiting_for_release_since());
  waited.reset();
  v1::ServerMessage res;
  res.set_sequence(4);
  res.mutable_resume()->set_release_up_to_sequence(4);
  r.Apply(res, 9.0, &waited);
  EXPECT_FALSE(waited);
}

TEST(SimRobotTest, HoldStopsAtOnceAndResumeContinues) {
  SimRobot r("R1", {0, 0}, 1.0);
  r.Apply(Plan(1));
  Events run;
  StepTo(r, 0.0, 1.0, 0.5, run);
  v1::ServerMessage h;
  h.set_sequence(2);
  h.mutable_hold()->set_reason("test");
  r.Apply(h);
  StepTo(r, 1.5, 5.0, 0.5, run);
  EXPECT_NEAR(r.position().x(), 1.0, 1e-9);
  EXPECT_TRUE(r.held());
  v1::ServerMessage res;
  res.set_sequence(3);
  res.mutable_resume();
  r.Apply(res);
  StepTo(r, 5.5, 6.0, 0.5, run);
  EXPECT_NEAR(r.position().x(), 2.0, 1e-9);
}

TEST(SimRobotTest, RepeatedMessagesAreHarmless) {
  SimRobot r("R1", {0, 0}, 1.0);
  EXPECT_TRUE(r.Apply(Plan(1)));
  Events run;
  StepTo(r, 0.0, 3.0, 0.1, run);
  EXPECT_FALSE(r.Apply(Plan(1)));  // the same sequence again: ignored
  EXPECT_EQ(r.last_applied_sequence(), 1u);
  // The server re-sends the plan under a new sequence after a reconnect: reached
  // waypoints are not driven or reported again.
  EXPECT_TRUE(r.Apply(Plan(7)));
  StepTo(r, 3.1, 12.0, 0.1, run);
  EXPECT_EQ(run.Names(),
            (std::vector<std::string>{"wp1", "wp2", "wp3", "picked", "wp4", "dropped"}));
  EXPECT_EQ(r.Hello().hello().last_acked_sequence(), 7u);
}

TEST(SimRobotTest, ReportsAFinishedDropAgainWhenTheServerStillPlansIt) {
  SimRobot r("R1", {0, 0}, 1.0);
  r.Apply(Plan(1));
  Events run;
  StepTo(r, 0.0, 10.5, 0.1, run);  // standing at the drop, working: not finished yet
  EXPECT_TRUE(r.Apply(Plan(2)));  // a re-sent plan (reconnect) while the drop is under way
  StepTo(r, 10.6, 12.0, 0.1, run);
  EXPECT_EQ(run.Names(),
            (std::vector<std::string>{"wp1", "wp2", "wp3", "picked", "wp4", "dropped"}));
  // The server re-sends the plan with the finished drop (it missed the event): reported again,
  // once, for the same order; nothing is driven again.
  EXPECT_TRUE(r.Apply(Plan(3)));
  StepTo(r, 12.1, 14.0, 0.1, run);
  EXPECT_EQ(run.Names(), (std::vector<std::string>{"wp1", "wp2", "wp3", "picked", "wp4",
                                                   "dropped", "dropped"}));
  EXPECT_EQ(run.events.back().task_event().order_id(), "o1");
  EXPECT_EQ(run.events.back().task_event().waypoint_sequence(), 4u);
  EXPECT_TRUE(r.idle());
  // A plan that no longer holds that drop (the server got it) repeats nothing.
  v1::ServerMessage next = Plan(4);
  for (auto& w : *next.mutable_assignment()->mutable_waypoints()) w.set_sequence(w.sequence() + 10);
  r.Apply(next);
  const std::size_t before = run.events.size();
  StepTo(r, 14.1, 14.2, 0.1, run);
  for (std::size_t i = before; i < run.events.size(); ++i) {
    EXPECT_FALSE(run.events[i].has_task_event());
  }
}

TEST(SimRobotTest, MutedRobotStandsStillAndReportsNothing) {
  SimRobot r("R1", {0, 0}, 1.0);
  r.Apply(Plan(1));
  Events run;
  StepTo(r, 0.0, 1.0, 0.1, run);
  r.set_muted();
  EXPECT_TRUE(r.muted());
  const std::size_t before = run.events.size();
  StepTo(r, 1.1, 20.0, 0.1, run);
  EXPECT_NEAR(r.position().x(), 1.0, 1e-6);
  EXPECT_EQ(run.events.size(), before);
  EXPECT_EQ(r.speed(), 0.0);
}

TEST(SimRobotTest, CancelStopsAtTheNextWaypointWithoutWorking) {
  SimRobot r("R1", {0, 0}, 1.0);
  r.Apply(Plan(1));
  Events run;
  StepTo(r, 0.0, 2.5, 0.1, run);  // past waypoint 2, driving to the pick
  v1::ServerMessage c;
  c.set_sequence(2);
  c.mutable_cancel()->add_order_ids("o1");
  r.Apply(c);
  StepTo(r, 2.6, 20.0, 0.1, run);
  EXPECT_NEAR(r.position().x(), 4.0, 1e-9);
  EXPECT_NEAR(r.position().y(), 0.0, 1e-9);
  EXPECT_EQ(run.Names(), (std::vector<std::string>{"wp1", "wp2", "wp3"}));
  EXPECT_TRUE(r.idle());
}

TEST(SimRobotTest, StalledRobotDoesNotMoveSlowRobotLags) {
  SimRobot stalled("R1", {0, 0}, 1.0), slow("R2", {0, 0}, 1.0);
  stalled.Apply(Plan(1));
  slow.Apply(Plan(1));
  stalled.set_stalled(true);
  slow.set_slow_factor(0.5);
  Events run;
  StepTo(stalled, 0.0, 2.0, 0.1, run);
  StepTo(slow, 0.0, 2.0, 0.1, run);
  EXPECT_EQ(stalled.position().x(), 0.0);
  EXPECT_EQ(stalled.Report().state_report().state(), v1::ROBOT_STATE_FAULT);
  EXPECT_NEAR(slow.position().x(), 1.0, 1e-6);
}

}  // namespace
}  // namespace dispatch::clients
