// Liveness on the dispatch core (SimulateOnCore): seeded random streams on small dense grids,
// every lane a bidirectional single lane, picks and drops inside one-cell aisles, with the
// product's settings (dispatchd's and dispatch-sim's defaults). Every order completes or fails
// saying it was blocked; no run waits until the time limit; every run is safe on the robots'
// true positions.
#include "engine/sim/core_stream.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "tests/engine/sim/stream_test_support.h"

namespace dispatch::engine::testing {
namespace {

// Up to 2000 s, awards planned by `planner`, with the product's settings, checked for safety
// at every step.
StreamConfig DenseGridConfig(PlannerKind planner) {
  StreamConfig c;
  c.max_time = 2000;
  c.check_safety = true;
  c.allocation.formation_max_queue = 1;  // the product's formation settings
  c.one_formation_per_pick = true;
  c.allocation.planner = planner;
  c.traffic.execution = DefaultPlanExecution(planner);  // as dispatchd and dispatch-sim drive it
  return c;
}

// `n` robots and 40 random orders (seed `seed`, a `formation_share` of them formation orders,
// one every 2 s on average) on `w`, under DenseGridConfig(planner); `orders` gets the orders.
Result<StreamResult> DenseGridRun(const World& w, std::size_t n, std::uint64_t seed, double formation_share,
                                  PlannerKind planner, std::vector<Order>& orders) {
  auto robots = PlaceRobots(*w.map, n);
  RandomOrderOptions ro;
  ro.count = 40;
  ro.seed = seed;
  ro.interval = 2.0;
  ro.formation_share = formation_share;
  auto random = RandomOrders(*w.map, ro);
  if (!robots.ok()) return robots.error();
  if (!random.ok()) return random.error();
  orders = std::move(random).value();
  return SimulateOnCore(w.map, w.routes, *robots, orders, DenseGridConfig(planner));
}

// 4, 6 and 8 robots on each of DenseGrids(), seeds 1..5 (DenseGridRun). Returns (completed,
// total).
std::pair<std::size_t, std::size_t> CoreDenseGridLiveness(double formation_share,
                                                          PlannerKind planner = PlannerKind::kRules) {
  std::size_t total = 0, completed = 0;
  for (const std::string& rows : DenseGrids()) {
    const World w = GridWorld(rows);
    for (std::size_t n : {4u, 6u, 8u}) {
      for (std::uint64_t seed = 1; seed <= 5; ++seed) {
        SCOPED_TRACE("robots " + std::to_string(n) + " seed " + std::to_string(seed));
        std::vector<Order> orders;
        auto r = DenseGridRun(w, n, seed, formation_share, planner, orders);
        EXPECT_TRUE(r.ok()) << r.error().message;
        if (!r.ok()) continue;
        ExpectSane(w, orders, *r, DenseGridConfig(planner));  // nothing ran into the time limit
        EXPECT_TRUE(r->safety.has_value() && r->safety->ok())
            << (r->safety && !r->safety->ok() ? r->safety->violations.front().Describe() : std::string("no check"));
        EXPECT_GE(r->overall_min_distance, 0.6 - 1e-9);  // point clearance (eps1)
        for (const StreamOrderOutcome& o : r->orders) {
          if (!o.completed) {
            EXPECT_NE(o.failure.find("blocked"), std::string::npos) << o.order_id << ": " << o.failure;
          }
        }
        total += r->orders.size();
        completed += r->completed;
      }
    }
  }
  return {completed, total};
}

// Found here, each a run that waited until the time limit (or a safety violation) before its
// fix: a robot re-planning back and forth between two aisles, its wait clock reset by every
// detour (TrafficController: a detour livelock is blocked); an idle robot inside a one-robot
// corridor that could not step aside, the corridor held by one standing behind it.
TEST(CoreLivenessTest, SingleOrdersOnSmallDenseGrids) {
  const auto [completed, total] = CoreDenseGridLiveness(0.0);
  std::printf("core liveness: %zu/%zu orders completed\n", completed, total);
  EXPECT_GE(static_cast<double>(completed), 0.95 * static_cast<double>(total));
}

// A formation's envelope fills a one-cell aisle. Found here before their fixes: a team leaving
// its drop waited for ever on its own member placed in the corridor it held; members freed by a
// team that left its drop never bid again (no round was due); a stray (a member left in its
// slot) given a formation that broke up lost its standing and a robot drove up to it; a member
// backed off away from its rendezvous joined there and drove through a robot to its slot; a
// team waited on its own member standing on its rendezvous point, never on the robot in the
// way; orders went round blocked robots for ever.
TEST(CoreLivenessTest, FormationOrdersOnSmallDenseGrids) {
  const auto [completed, total] = CoreDenseGridLiveness(0.2);
  std::printf("core liveness with formations: %zu/%zu orders completed\n", completed, total);
  EXPECT_GE(static_cast<double>(completed), 0.9 * static_cast<double>(total));
}

// The planned planners on the same streams, the traffic controller as their safety net (issue
// 16 §3). Found here before their fixes (2026-12-06; 1,119 and 1,129 of the 1,200 single orders
// completed, one run still open at its limit): a robot drove round two wait cycles in turn,
// each broken by its detour into the other, for 1,900 s while five robots waited on it (a
// robot in a detour livelock now acts last); a head-on's detour led back to the point a robot
// had just gone round; a robot inside a one-cell aisle backed off one cell and came back,
// thousands of times, while the robot at the aisle's end waited on it.
TEST(CoreLivenessTest, PlannedPlannersOnSmallDenseGrids) {
  for (PlannerKind planner : {PlannerKind::kTimeWindows, PlannerKind::kConflictElimination}) {
    SCOPED_TRACE(PlannerName(planner));
    for (double share : {0.0, 0.2}) {
      const auto [completed, total] = CoreDenseGridLiveness(share, planner);
      std::printf("core liveness, %s, %.0f%% formations: %zu/%zu orders completed\n", PlannerName(planner),
                  100.0 * share, completed, total);
      EXPECT_GE(static_cast<double>(completed), 0.96 * static_cast<double>(total));
    }
  }
}

// Found here (2026-12-07), on the first grid with 6 robots, seed 1, the time windows: a robot
// bound for the left-hand drop went round the right-hand corridor, held the other way by a
// robot waiting to come up it; met head-on on the way round, it backed off, and its back-off
// led straight back into that corridor: back and forth for 120 s, until it and the robot
// waiting for it were blocked (36 of 40 completed). A back-off now keeps off the corridor its
// robot's last detour went round while the robot it waited on holds it (StickyCorridor).
// Since allocation rounds replay queues from the next prediction bucket (2026-12-07) that seed
// goes otherwise; on seed 8 the rule still decides: without it a robot was blocked re-planning
// back and forth round a corridor and two more waiting behind (37 of 40).
TEST(CoreLivenessTest, ABackOffDoesNotLeadBackIntoTheCorridorADetourWentRound) {
  const World w = GridWorld(DenseGrids().front());
  std::vector<Order> orders;
  auto r = DenseGridRun(w, 6, 8, 0.0, PlannerKind::kTimeWindows, orders);
  ASSERT_TRUE(r.ok()) << r.error().message;
  for (const StreamOrderOutcome& o : r->orders) EXPECT_TRUE(o.completed) << o.order_id << ": " << o.failure;
  ASSERT_TRUE(r->safety.has_value());
  EXPECT_TRUE(r->safety->ok()) << r->safety->violations.front().Describe();
}

// Found here (2026-12-07), on the first grid: an idle robot standing in a one-robot corridor
// (a service point inside) that a robot waited to enter was nudged one point along it and, at
// the next nudge, one point back, for 120 s, holding the corridor all along, until the robot
// waiting was blocked (rules with 20% formations, 4 robots, seed 21; the time windows, seed 3:
// 39 of 40 each). A nudged robot with nowhere to go now leaves such a corridor or stays
// (TryBackOff, LeaveCorridor).
TEST(CoreLivenessTest, AnIdleRobotNudgedInAOneRobotCorridorLeavesItOrStays) {
  const World w = GridWorld(DenseGrids().front());
  for (const auto& [planner, seed] : {std::pair{PlannerKind::kRules, 21}, std::pair{PlannerKind::kTimeWindows, 3}}) {
    SCOPED_TRACE(PlannerName(planner));
    std::vector<Order> orders;
    auto r = DenseGridRun(w, 4, static_cast<std::uint64_t>(seed), 0.2, planner, orders);
    ASSERT_TRUE(r.ok()) << r.error().message;
    for (const StreamOrderOutcome& o : r->orders) EXPECT_TRUE(o.completed) << o.order_id << ": " << o.failure;
    ASSERT_TRUE(r->safety.has_value());
    EXPECT_TRUE(r->safety->ok()) << r->safety->violations.front().Describe();
  }
}

// Found here (2026-12-07), on the first grid with 6 robots, seed 10, the time windows: a robot
// planned out of the way and back (c4 -> c3 -> c13 -> c3 -> c4, its pick at c4) met a head-on
// at c4; the head-on's "detour" to its route's end, where it stood, was that point alone, so
// the loop was dropped, its next waypoints were never released and it stood at c4 for the
// rest of the run with every other robot waiting behind it. A head-on now has no detour of a
// single point (TrafficController, HeadOn).
TEST(CoreLivenessTest, ALoopBackToWhereTheRobotStandsSurvivesAHeadOn) {
  const World w = GridWorld(DenseGrids().front());
  std::vector<Order> orders;
  auto r = DenseGridRun(w, 6, 10, 0.0, PlannerKind::kTimeWindows, orders);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ExpectSane(w, orders, *r, DenseGridConfig(PlannerKind::kTimeWindows));  // nothing ran into the time limit
  EXPECT_GE(r->completed, 38u);
  ASSERT_TRUE(r->safety.has_value());
  EXPECT_TRUE(r->safety->ok()) << r->safety->violations.front().Describe();
}

}  // namespace
}  // namespace dispatch::engine::testing
