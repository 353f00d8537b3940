// SimulateOnCore (engine/sim/core_stream.h): the service's DispatchCore driven by in-process
// robots - the seed's task tables, a 200-order stream under the three strategies, determinism
// and the errors.
#include "engine/sim/core_stream.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include "engine/cli/scenario.h"
#include "tests/engine/sim/stream_test_support.h"

namespace dispatch::engine::testing {
namespace {

std::vector<Order> TaskTable(const World& w, const std::string& name) {
  auto orders = LoadTaskTableOrders(*w.map, std::string(DISPATCH_SHARED_DIR) + "/scenarios/" + name);
  if (!orders.ok()) throw std::runtime_error(orders.error().message);
  return std::move(orders).value();
}

// The tables submitted `times` times at once, named as dispatch-sim stream --repeat names
// them (with two tables, copy k of table 2's task T3 is T3.2-k).
std::vector<Order> Repeated(const World& w, const std::vector<std::string>& tables, int times) {
  std::vector<Order> orders;
  for (int k = 1; k <= times; ++k) {
    for (std::size_t i = 0; i < tables.size(); ++i) {
      for (Order o : TaskTable(w, tables[i])) {
        if (tables.size() > 1) o.id += "." + std::to_string(i + 1);
        o.id += "-" + std::to_string(k);
        o.client_id = o.id;
        orders.push_back(std::move(o));
      }
    }
  }
  // In release order, as the simulator takes them (and ExpectSane reads its outcomes).
  std::stable_sort(orders.begin(), orders.end(), [](const Order& a, const Order& b) {
    return a.release_time.value_or(a.created_time) < b.release_time.value_or(b.created_time);
  });
  return orders;
}

std::vector<FleetRobot> Fleet(const World& w, std::size_t n) {
  auto robots = PlaceRobots(*w.map, n);
  if (!robots.ok()) throw std::runtime_error(robots.error().message);
  return std::move(robots).value();
}

StreamConfig Config(AllocationStrategy strategy = AllocationStrategy::kAuction, double zeta = 100.0) {
  StreamConfig c;
  c.strategy = strategy;
  c.allocation.zeta = zeta;
  c.max_time = 20000;
  return c;
}

// Every order completes, robots keep eps1 (0.6 m) apart and the gate granted intersections.
void ExpectCompleteAndClear(const World& w, const std::vector<Order>& orders, const StreamResult& r,
                            const StreamConfig& c) {
  ExpectSane(w, orders, r, c);
  EXPECT_EQ(r.completed, orders.size());
  EXPECT_GE(r.overall_min_distance, 0.6 - 1e-9) << r.min_pair << " at " << r.min_time;
  EXPECT_TRUE(r.too_close.empty()) << r.too_close.front();
  EXPECT_TRUE(r.blocked.empty()) << r.blocked.front();
  EXPECT_GT(r.traffic.grants, 0u);
  if (c.check_safety) {
    ASSERT_TRUE(r.safety.has_value());
    EXPECT_TRUE(r.safety->ok()) << r.safety->violations.front().Describe();
  }
}

TEST(CoreStreamTest, TaskTablesCompleteOnTheCoreWithClearance) {
  const World w = Chu();
  for (const char* table : {"chu2024-table1.csv", "chu2024-table2.csv"}) {
    SCOPED_TRACE(table);
    const std::vector<Order> orders = TaskTable(w, table);
    ASSERT_FALSE(orders.empty());
    StreamConfig c = Config();
    c.check_safety = true;  // on the robots' true positions, crossings in intersections too
    auto r = SimulateOnCore(w.map, w.routes, Fleet(w, 18), orders, c);
    ASSERT_TRUE(r.ok()) << r.error().message;
    ExpectCompleteAndClear(w, orders, *r, c);
  }
}

TEST(CoreStreamTest, RandomStreamAuctionBeatsGreedyOnTheCore) {
  const World w = Chu();
  const Stream s = ChuStream(w, 200, 1);
  double makespan[3] = {0, 0, 0};
  int k = 0;
  for (auto [strategy, zeta] : {std::pair{AllocationStrategy::kAuction, 100.0}, std::pair{AllocationStrategy::kAuction, 0.0},
                                std::pair{AllocationStrategy::kGreedy, 0.0}}) {
    SCOPED_TRACE(k);
    const StreamConfig c = Config(strategy, zeta);
    auto r = SimulateOnCore(w.map, w.routes, s.robots, s.orders, c);
    ASSERT_TRUE(r.ok()) << r.error().message;
    ExpectCompleteAndClear(w, s.orders, *r, c);
    std::set<std::string> used;
    for (const StreamOrderOutcome& o : r->orders) used.insert(o.robot);
    EXPECT_EQ(used.size(), s.robots.size());  // the whole fleet works
    makespan[k++] = r->makespan;
  }
  // The auction (with and without the traffic term) finishes the stream before greedy.
  EXPECT_LT(makespan[0], makespan[2]);
  EXPECT_LT(makespan[1], makespan[2]);
}

// Issue 16 §3: the time-window planner and the heat routing are selectable in the simulator;
// on the random stream every order completes with eps1 kept, and the tables complete with the
// safety check clean.
class CorePlannerTest : public ::testing::TestWithParam<std::pair<PlannerKind, RoutingKind>> {};

TEST_P(CorePlannerTest, CompletesTheStreamAndTheTables) {
  const World w = Chu();
  const Stream s = ChuStream(w, 200, 1);
  StreamConfig c = Config();
  c.allocation.planner = GetParam().first;
  c.allocation.routing = GetParam().second;
  auto r = SimulateOnCore(w.map, w.routes, s.robots, s.orders, c);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ExpectCompleteAndClear(w, s.orders, *r, c);
  c.check_safety = true;
  for (const char* table : {"chu2024-table1.csv", "chu2024-table2.csv"}) {
    SCOPED_TRACE(table);
    const std::vector<Order> orders = TaskTable(w, table);
    auto t = SimulateOnCore(w.map, w.routes, Fleet(w, 18), orders, c);
    ASSERT_TRUE(t.ok()) << t.error().message;
    ExpectCompleteAndClear(w, orders, *t, c);
  }
}

INSTANTIATE_TEST_SUITE_P(Planners, CorePlannerTest,
                         ::testing::Values(std::pair{PlannerKind::kTimeWindows, RoutingKind::kFloyd},
                                           std::pair{PlannerKind::kRules, RoutingKind::kHeat}),
                         [](const auto& info) {
                           return std::string(info.param.first == PlannerKind::kTimeWindows ? "TimeWindows" : "HeatRouting");
                         });

// Issue 16 §1: turning time enters the plans (BuildPlan) and the robots' motion (WaypointRobot)
// together: the stream still completes with eps1 kept, later than without turning.
TEST(CoreStreamTest, TurningTimeSlowsTheStreamAndEveryOrderStillCompletes) {
  const World w = Chu();
  const Stream s = ChuStream(w, 200, 1);
  StreamConfig c = Config();
  auto straight = SimulateOnCore(w.map, w.routes, s.robots, s.orders, c);
  c.allocation.turn_time = 1.0;
  auto turning = SimulateOnCore(w.map, w.routes, s.robots, s.orders, c);
  ASSERT_TRUE(straight.ok() && turning.ok());
  ExpectCompleteAndClear(w, s.orders, *turning, c);
  EXPECT_GT(turning->makespan, straight->makespan);
  EXPECT_GT(turning->mean_completion, straight->mean_completion);
}

TEST(CoreStreamTest, RunsAreDeterministic) {
  const World w = Chu();
  const Stream s = ChuStream(w, 40, 3);
  const StreamConfig c = Config();
  auto a = SimulateOnCore(w.map, w.routes, s.robots, s.orders, c);
  auto b = SimulateOnCore(w.map, w.routes, s.robots, s.orders, c);
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(a->orders.size(), b->orders.size());
  for (std::size_t i = 0; i < a->orders.size(); ++i) {
    EXPECT_EQ(a->orders[i].robot, b->orders[i].robot);
    EXPECT_EQ(a->orders[i].completion_time, b->orders[i].completion_time);
  }
  EXPECT_EQ(a->traffic.grants, b->traffic.grants);
  EXPECT_EQ(a->total_distance, b->total_distance);
}

TEST(CoreStreamTest, RejectsWhatItCannotRun) {
  const World w = Chu();
  const Stream s = ChuStream(w, 5, 1);
  EXPECT_FALSE(SimulateOnCore(w.map, w.routes, {}, s.orders, Config()).ok());
  StreamConfig zero = Config();
  zero.time_step = 0;
  EXPECT_FALSE(SimulateOnCore(w.map, w.routes, s.robots, s.orders, zero).ok());
  EXPECT_FALSE(SimulateOnCore(nullptr, w.routes, s.robots, s.orders, Config()).ok());

  std::vector<FleetRobot> shared = {s.robots[0], s.robots[1]};
  shared[1].start = shared[0].start;
  auto same = SimulateOnCore(w.map, w.routes, shared, s.orders, Config());
  ASSERT_FALSE(same.ok());
  EXPECT_NE(same.error().message.find("starts where another robot stands"), std::string::npos);

  std::vector<Order> formation = {s.orders[0]};
  formation[0].formation = true;
  auto two = SimulateOnCore(w.map, w.routes, {s.robots[0], s.robots[1]}, formation, Config());
  ASSERT_FALSE(two.ok());
  EXPECT_NE(two.error().message.find("needs 3 robots"), std::string::npos) << two.error().message;
}

// The formation freeze (README "Formations on the dispatch core"): seed Table 1 submitted three
// times at once (9 formation orders, three teams to each first pick). With every order awarded
// at once the queued teams lock up; with a robot bidding only while it has no order
// (max_queue 1) and one formation at a time heading for a first pick, every order completes.
TEST(CoreStreamTest, TableOneThreeTimesCompletesWithShortQueuesAndOneFormationPerPick) {
  const World w = Chu();
  const std::vector<Order> orders = Repeated(w, {"chu2024-table1.csv"}, 3);
  StreamConfig c = Config();
  c.max_time = 3000;
  c.allocation.max_queue = 1;
  c.one_formation_per_pick = true;
  c.check_safety = true;
  auto r = SimulateOnCore(w.map, w.routes, Fleet(w, 18), orders, c);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ExpectSane(w, orders, *r, c);
  EXPECT_EQ(r->completed, orders.size()) << (r->blocked.empty() ? std::string() : r->blocked.front());
  ASSERT_TRUE(r->safety.has_value());
  EXPECT_TRUE(r->safety->ok()) << r->safety->violations.front().Describe();
}

// dispatchd's and dispatch-sim's formation settings (formation_max_queue 1, one formation per
// pick), up to 3000 s, checked on the robots' true positions.
StreamConfig ProductFormationConfig() {
  StreamConfig c = Config();
  c.max_time = 3000;
  c.check_safety = true;
  c.allocation.formation_max_queue = 1;
  c.one_formation_per_pick = true;
  return c;
}

// The product's formation settings (dispatchd's and dispatch-sim's defaults): a formation takes
// only robots with nothing queued (formation_max_queue 1; single orders queue as before) and
// one formation at a time heads for a first pick. Seed Table 1 four times at once (24 orders,
// 12 formations): every order completes, safely; the paper's settings (every order awarded at
// once, members with queues) leave teams waiting for their members and complete fewer.
TEST(CoreStreamTest, TableOneFourTimesCompletesWhenFormationsTakeFreeRobots) {
  const World w = Chu();
  const std::vector<Order> orders = Repeated(w, {"chu2024-table1.csv"}, 4);
  const StreamConfig c = ProductFormationConfig();
  auto r = SimulateOnCore(w.map, w.routes, Fleet(w, 18), orders, c);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ExpectSane(w, orders, *r, c);
  EXPECT_EQ(r->completed, orders.size()) << (r->blocked.empty() ? std::string() : r->blocked.front());
  ASSERT_TRUE(r->safety.has_value());
  EXPECT_TRUE(r->safety->ok()) << r->safety->violations.front().Describe();
  StreamConfig paper = Config();
  paper.max_time = 3000;
  auto p = SimulateOnCore(w.map, w.routes, Fleet(w, 18), orders, paper);
  ASSERT_TRUE(p.ok()) << p.error().message;
  EXPECT_LT(p->completed, r->completed);
}

// 18 robots serve `orders` on the core for up to 3000 s; CheckSafety over the robots' true
// positions finds nothing.
void ExpectSafeToTheEnd(const World& w, const std::vector<Order>& orders) {
  StreamConfig c = Config();
  c.max_time = 3000;
  c.check_safety = true;
  auto r = SimulateOnCore(w.map, w.routes, Fleet(w, 18), orders, c);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_TRUE(r->safety.has_value());
  EXPECT_TRUE(r->safety->ok()) << r->safety->violations.front().Describe();
}

// Members on their way to one rendezvous may stand closer than eps1 (teammates are exempt
// from each other). When their team breaks up before they have joined it, they stay exempt
// until each has reached its next point (the gate's former team), as joined members do; and a
// member of two broken-up teams in turn stays exempt from both. Seed Tables 1 and 2 ten times
// at once (the freeze), checked on the robots' true positions: two members waiting 0.4 m
// apart for their rendezvous lost the exemption the moment it broke up (t = 239.4 s), and
// later a member of two teams lost the older one (t = 403.2 s, 0.400 m).
TEST(CoreStreamTest, MembersOnTheirWayStayExemptFromEachOtherWhenTheirTeamBreaksUp) {
  const World w = Chu();
  ExpectSafeToTheEnd(w, Repeated(w, {"chu2024-table1.csv", "chu2024-table2.csv"}, 10));
}

// The same burst with the product's formation settings (formations take robots with nothing
// queued, one at a time per first pick) completes nine in ten orders (2 of 140 with the
// paper's), and stays safe. Only a member that stands by a teammate stays exempt from its
// team once it breaks up: checked on true positions, a member blocked 1.7 m short of its
// rendezvous stayed its teammates' mate after the break-up, and one leaving its slot drove up
// to it at 0.400 m (t = 1770 s). Since teams broken up leave their point one member at a time
// and a member left in its slot is seen where it stands, nothing waits for ever either: the
// orders that fail say they were blocked.
// The burst of seed Tables 1 and 2 ten times at once on 18 robots, with the product's formation
// settings and time step `dt`: sane, safe on true positions, every order that fails says it was
// blocked, and at least `share` of them complete.
void ExpectBurstEndsSafely(double dt, double share) {
  const World w = Chu();
  const std::vector<Order> orders = Repeated(w, {"chu2024-table1.csv", "chu2024-table2.csv"}, 10);
  StreamConfig c = ProductFormationConfig();
  c.time_step = dt;
  auto r = SimulateOnCore(w.map, w.routes, Fleet(w, 18), orders, c);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ExpectSane(w, orders, *r, c);
  for (const StreamOrderOutcome& o : r->orders) {
    if (!o.completed) {
      EXPECT_NE(o.failure.find("blocked"), std::string::npos) << o.order_id << ": " << o.failure;
    }
  }
  ASSERT_TRUE(r->safety.has_value());
  EXPECT_TRUE(r->safety->ok()) << r->safety->violations.front().Describe();
  EXPECT_GE(static_cast<double>(r->completed), share * static_cast<double>(orders.size()))
      << r->completed << " of " << orders.size();
}

TEST(CoreStreamTest, AMemberStuckFarFromItsRendezvousIsNoTeammateOnceTheTeamBreaksUp) {
  ExpectBurstEndsSafely(0.1, 0.9);
}

// The same burst in coarse steps, as a service's tick at a time scale drives it (0.4 s and
// 0.5 s instead of 0.1 s), checked on true positions. Found here: in the step a member of a
// broken-up team drove out of its former team and lost the exemption, a former teammate that
// asked later in the step was still exempt from it and was sent to a point 0.500 m from it
// (0.4 s); a formation stopped inside intersection I5-4 before a drop that stayed held closed
// a wait cycle nobody in it could back off from, and 21 orders failed blocked (0.5 s: 119/140,
// now 140/140; the controller backs it off through the intersection's other exit).
TEST(CoreStreamTest, TheBurstInCoarseStepsStaysSafeAndFailsOnlyBlocked) {
  for (double dt : {0.4, 0.5}) {
    SCOPED_TRACE("dt " + std::to_string(dt));
    ExpectBurstEndsSafely(dt, 0.8);
  }
}

// A team whose order goes before its drop (a member blocked, the orders put back) leaves the
// point it stands on one member at a time, as after a drop, its agent's envelope over the
// slots until each has driven off (GateImpl::DissolveTeam); one with no way off within T_w2
// breaks up where it stands, and a member left in its slot is seen standing there
// (TrafficController::SetStanding). Checked on true positions with the product's formation
// settings (200 random orders, 30% formations, seed 6): members broken up at once were left
// in their slots off the floor, and strangers drove up to them (0.231 m and 0.400 m at 1124 s).
TEST(CoreStreamTest, ABrokenUpTeamLeavesItsPointOneMemberAtATime) {
  const World w = Chu();
  const Stream s = ChuStream(w, 200, 6, 0.3);
  const StreamConfig c = ProductFormationConfig();
  auto r = SimulateOnCore(w.map, w.routes, s.robots, s.orders, c);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_TRUE(r->safety.has_value());
  EXPECT_TRUE(r->safety->ok()) << r->safety->violations.front().Describe();
  EXPECT_GE(r->completed, 150u);
}

// Before it reaches the first waypoint of a new plan, a robot counts as one with the team of
// that waypoint's order (not with none, as the plan's anchor serves no order). Seed Table 1
// four times at once, checked on true positions: a formation member whose new plan began with
// its next formation, off the floor beside the rendezvous, was taken for a stranger to its new
// teammates, and one drove into its slot past it at 0.20 m without either being exempt.
TEST(CoreStreamTest, ARobotCountsWithItsNextTeamBeforeItsFirstWaypoint) {
  const World w = Chu();
  ExpectSafeToTheEnd(w, Repeated(w, {"chu2024-table1.csv"}, 4));
}

// StreamConfig::trace_robots: one line per traced robot and step of the window, with where it
// really is and the gate's view of it.
TEST(CoreStreamTest, TracesTheChosenRobotsInTheWindow) {
  const World w = Chu();
  const Stream s = ChuStream(w, 10, 1);
  StreamConfig c = Config();
  c.trace_robots = {"R2", "nobody"};
  c.trace_from = 1.0;
  c.trace_to = 1.5;
  auto r = SimulateOnCore(w.map, w.routes, s.robots, s.orders, c);
  ASSERT_TRUE(r.ok()) << r.error().message;
  std::vector<std::string> lines;
  for (const std::string& l : r->trace) {
    if (l.find("note:") == std::string::npos) lines.push_back(l);
  }
  ASSERT_EQ(lines.size(), 6u);  // 1.0, 1.1, ..., 1.5 s
  EXPECT_EQ(lines.front().rfind("1.0 s: R2 at (", 0), 0u) << lines.front();
  EXPECT_EQ(lines.back().rfind("1.5 s: R2 at (", 0), 0u) << lines.back();
  EXPECT_NE(lines.front().find("released"), std::string::npos) << lines.front();  // the gate's view
}

// When a team breaks up, its members stand in their slots around the team's point: each stays
// exempt from its former teammates until it has driven out of the formation's envelope there
// and none of them still stands in it (as after a drop), not merely until its next point. 200
// random orders with 20% formations (seed 3), checked on true positions: a member that
// reached its next point 0.5 m from the team's point lost the exemption while a teammate still
// stood in its slot; back on the floor, that teammate drove past it at 0.50 m (t = 292.3 s).
// Seed 2 had the same fault (0.553 m at 580.0 s).
TEST(CoreStreamTest, MembersOfABrokenUpTeamStayExemptUntilAllHaveDrivenOff) {
  const World w = Chu();
  for (std::uint64_t seed : {2u, 3u}) {
    SCOPED_TRACE(seed);
    ExpectSafeToTheEnd(w, ChuStream(w, 200, seed, 0.2).orders);
  }
}

// A robot counts with all three of its teams at once: the one it approaches and the last two
// it left, while it has not driven off from them. Seed Table 1 five times at once, checked on
// true positions: a member of two broken-up teams in turn that was given its next formation
// kept only two keys, dropped the older team's and stood 0.400 m from a member of that team
// still in its slot (t = 378.3 s). The same run had a member that joined its team on a point
// of intersection 33 recorded as the team's agent while it still drove to its slot on its own
// controller agent, a crossing the controller had not allowed (112.3 s): a member is recorded
// with its team once the team's agent stands for it (GateRobotState::moved_by_team). And of its
// two former teams the one whose members still stand beside it is kept: once blocked robots'
// waits were timed afresh after their recovery, a robot blocked on a team's point, with two
// members of that team in their slots around it, was in two more teams in turn that broke up,
// dropped the first team and stood 0.231 m from those members (t = 663.8 s).
TEST(CoreStreamTest, ARobotCountsWithItsNextTeamAndTheTwoItLeft) {
  const World w = Chu();
  ExpectSafeToTheEnd(w, Repeated(w, {"chu2024-table1.csv"}, 5));
}

// A formation breaking up inside an intersection hands its grant to its members in their
// slots before its agent lets it go, and a robot put back on an intersection's point holds the
// grant: 300 random orders with 30% formations (seed 5), checked on true positions, had a
// robot granted a crossing the moment the team's agent was removed, around a member not back
// on the floor yet (t = 195.5 s), and another around a member placed there (199.5 s).
TEST(CoreStreamTest, ABrokenUpFormationHandsItsIntersectionGrantToItsMembers) {
  const World w = Chu();
  ExpectSafeToTheEnd(w, ChuStream(w, 300, 5, 0.3).orders);
}

}  // namespace
}  // namespace dispatch::engine::testing
