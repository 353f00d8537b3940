// Allocation rounds: a round over the robots' current state and queues, awards spliced into
// assignments, queues replayed from stored plans.
#include "engine/dispatch/allocation_round.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "engine/dispatch/strategy.h"
#include "tests/engine/dispatch/dispatch_test_support.h"

namespace dispatch::engine {
namespace {

using testing_util::Chu2024;
using testing_util::Chu2024Routes;
using testing_util::MakeOrder;
using testing_util::PointsOfKind;

RoundRunner Runner(const std::string& strategy = "auction") {
  return RoundRunner(Chu2024(), Chu2024Routes(), AllocationConfig{}, std::move(MakeAllocator(strategy)).value());
}

TEST(AllocationRound, NaturalAndAllocationOrder) {
  EXPECT_TRUE(NaturalLess("R2", "R10"));
  EXPECT_FALSE(NaturalLess("R10", "R2"));
  EXPECT_TRUE(NaturalLess("ord-999999", "ord-1000000"));
  EXPECT_TRUE(NaturalLess("R1", "R1a"));
  EXPECT_FALSE(NaturalLess("R1", "R1"));
  Order a, b;
  a.id = "ord-10";
  b.id = "ord-9";
  EXPECT_TRUE(AllocationOrderLess(b, a));  // same time: by id, naturally
  a.priority = 1;
  EXPECT_TRUE(AllocationOrderLess(a, b));  // priority first
  a.priority = b.priority = 0;
  a.created_time = 1.0;
  b.created_time = 2.0;
  EXPECT_TRUE(AllocationOrderLess(a, b));
}

TEST(AllocationRound, AwardsEveryOrderWithWholePlansForRobotsWithoutQueues) {
  const auto& map = *Chu2024();
  const auto parks = PointsOfKind(map, PointKind::kPark);
  const auto picks = PointsOfKind(map, PointKind::kPick);
  const auto drops = PointsOfKind(map, PointKind::kDrop);
  RoundInput input;
  input.now = 100.0;
  for (int i = 0; i < 3; ++i) input.robots.push_back({"R" + std::to_string(i + 1), parks.at(static_cast<std::size_t>(i) * 6), {}, 0, {}, {}});
  input.pending = {MakeOrder("o1", picks.at(3), drops.at(0), 1.0), MakeOrder("o2", picks.at(90), drops.at(9), 2.0)};
  RoundRunner runner = Runner();
  const RoundResult result = runner.Run(input);
  EXPECT_TRUE(result.notes.empty());
  ASSERT_EQ(result.awards.size(), 2u);
  for (const RoundAward& a : result.awards) {
    ASSERT_EQ(a.award.winners.size(), 1u);
    ASSERT_EQ(a.segments.size(), 1u);
    const auto& seg = a.segments[0];
    ASSERT_GE(seg.size(), 3u);
    const auto robot = std::find_if(input.robots.begin(), input.robots.end(),
                                    [&](const RoundRobot& r) { return r.id == a.award.winners[0]; });
    ASSERT_NE(robot, input.robots.end());
    EXPECT_EQ(seg.front().point, robot->start);  // a whole plan from where the robot is
    EXPECT_GE(seg.front().eta, input.now);
    EXPECT_EQ(seg.back().action, WaypointAction::kDrop);
    // Spliced into an empty assignment: a plan numbered from 0, anchored at the start.
    Assignment book;
    book.robot_id = robot->id;
    AppendOrder(book, a.order_id, seg, a.after_departure[0], true, input.now);
    EXPECT_EQ(book.order_ids, std::vector<std::string>{a.order_id});
    EXPECT_EQ(OrderOfWaypoint(book, book.plan.waypoints.size() - 1), a.order_id);
  }
}

TEST(AllocationRound, QueuesAreReplayedFromStoredPlansAndNewWorkFollowsThem) {
  const auto& map = *Chu2024();
  const auto parks = PointsOfKind(map, PointKind::kPark);
  const auto picks = PointsOfKind(map, PointKind::kPick);
  const auto drops = PointsOfKind(map, PointKind::kDrop);
  RoundRunner runner = Runner();
  // Round 1: one robot gets o1.
  RoundInput first;
  first.robots = {{"R1", parks.at(0), {}, 0, {}, {}}};
  auto o1 = MakeOrder("o1", picks.at(3), drops.at(0), 0.0);
  first.pending = {o1};
  RoundResult r1 = runner.Run(first);
  ASSERT_EQ(r1.awards.size(), 1u);
  Assignment book;
  book.robot_id = "R1";
  AppendOrder(book, "o1", r1.awards[0].segments[0], 0.0, true, 0.0);
  // Round 2, a few seconds later, with the robot past its first waypoints: o2 goes behind o1.
  RoundInput second;
  second.now = 5.0;
  RoundRobot robot{"R1", book.plan.waypoints.at(2).point, std::make_shared<const Assignment>(book), 2, {o1}, {}};
  second.robots = {robot};
  second.pending = {MakeOrder("o2", picks.at(40), drops.at(5), 4.0)};
  RoundResult r2 = runner.Run(second);
  EXPECT_TRUE(r2.notes.empty()) << r2.notes.front();
  ASSERT_EQ(r2.awards.size(), 1u);
  const RoundAward& a = r2.awards[0];
  ASSERT_EQ(a.segments.size(), 1u);
  ASSERT_FALSE(a.segments[0].empty());
  EXPECT_GT(a.after_departure[0], 0.0);  // after the replayed queue
  EXPECT_GE(a.segments[0].front().eta, a.after_departure[0]);
  // The bid counted the queue: the award starts where o1 ends (its drop), not at the robot.
  const std::uint64_t first_new = AppendOrder(book, "o2", a.segments[0], a.after_departure[0], false, 5.0);
  EXPECT_EQ(first_new, static_cast<std::uint64_t>(book.plan.waypoints.at(SegmentStart(book, 1)).seq));
  EXPECT_EQ(book.order_ids, (std::vector<std::string>{"o1", "o2"}));
  EXPECT_GE(book.plan.waypoints.at(SegmentStart(book, 1)).eta, book.plan.waypoints.at(SegmentStart(book, 1) - 1).departure());
}

// A batch strategy (PSO-GA, the exact assignment) commits a round's orders jointly, a robot's
// several orders in one round: each award still holds exactly the part of its robot's plan it
// added (the first a whole plan from the robot's start, each later one after the previous
// one's last departure).
class BatchStrategyRound : public ::testing::TestWithParam<const char*> {};

TEST_P(BatchStrategyRound, EachAwardHoldsThePartOfThePlanItAdded) {
  const auto& map = *Chu2024();
  const auto parks = PointsOfKind(map, PointKind::kPark);
  const auto picks = PointsOfKind(map, PointKind::kPick);
  const auto drops = PointsOfKind(map, PointKind::kDrop);
  RoundInput input;
  input.now = 10.0;
  for (int i = 0; i < 2; ++i) input.robots.push_back({"R" + std::to_string(i + 1), parks.at(static_cast<std::size_t>(i) * 9), {}, 0, {}, {}});
  for (int k = 0; k < 5; ++k) {
    const auto u = static_cast<std::size_t>(k);
    input.pending.push_back(MakeOrder("o" + std::to_string(k), picks.at(7 * u + 2), drops.at(u % drops.size()), k));
  }
  RoundRunner runner = Runner(GetParam());
  const RoundResult result = runner.Run(input);
  EXPECT_TRUE(result.notes.empty()) << result.notes.front();
  ASSERT_EQ(result.awards.size(), 5u);
  std::map<std::string, std::vector<const RoundAward*>> by_robot;
  for (const RoundAward& a : result.awards) {
    EXPECT_EQ(a.award.strategy, GetParam());
    ASSERT_EQ(a.award.winners.size(), 1u);
    by_robot[a.award.winners[0]].push_back(&a);
  }
  for (const auto& [robot, awards] : by_robot) {
    const RoundRobot& r = input.robots.at(robot == "R1" ? 0 : 1);
    Assignment book;
    book.robot_id = robot;
    for (std::size_t k = 0; k < awards.size(); ++k) {
      const RoundAward& a = *awards[k];
      ASSERT_FALSE(a.segments[0].empty());
      if (k == 0) {
        EXPECT_EQ(a.segments[0].front().point, r.start);
        EXPECT_EQ(a.after_departure[0], 0.0);
      } else {
        EXPECT_EQ(a.after_departure[0], awards[k - 1]->segments[0].back().departure()) << a.order_id;
        EXPECT_NE(a.segments[0].front().action, WaypointAction::kDrop);  // no waypoint twice
      }
      EXPECT_EQ(a.segments[0].back().action, WaypointAction::kDrop);
      AppendOrder(book, a.order_id, a.segments[0], a.after_departure[0], k == 0, input.now);
    }
    EXPECT_EQ(book.order_ids.size(), awards.size());
  }
}

INSTANTIATE_TEST_SUITE_P(AllocationRound, BatchStrategyRound, ::testing::Values("psoga", "exact"));

// A round's result in full: awards with every bid and the waypoints' exact times, and notes.
std::string Dump(const RoundResult& r) {
  std::ostringstream out;
  out.precision(17);
  for (const RoundAward& a : r.awards) {
    out << a.order_id << " -> " << a.award.reason << "\n";
    for (const Bid& b : a.award.bids) out << "  " << DescribeBid(b) << "\n";
    for (std::size_t k = 0; k < a.segments.size(); ++k) {
      out << "  after " << a.after_departure[k] << ":";
      for (const Waypoint& w : a.segments[k]) out << " " << w.point << "@" << w.eta << "+" << w.dwell;
      out << "\n";
    }
  }
  for (const std::string& n : r.notes) out << "note " << n << "\n";
  return out.str();
}

// What a round returns is a function of its input alone: rounds on one runner (which keeps its
// fleet and the robots' replayed queues from round to round) return what a new runner returns
// for each, whether robots move on, stand, wait into a later prediction bucket, or won awards
// that were never applied.
TEST(AllocationRound, AKeptFleetGivesWhatANewRunnerGives) {
  const auto& map = *Chu2024();
  const auto parks = PointsOfKind(map, PointKind::kPark);
  const auto picks = PointsOfKind(map, PointKind::kPick);
  const auto drops = PointsOfKind(map, PointKind::kDrop);
  RoundRunner kept = Runner();
  std::vector<RoundRobot> robots;
  for (std::size_t i = 0; i < 4; ++i) robots.push_back({"R" + std::to_string(i + 1), parks.at(i * 5), {}, 0, {}, {}});
  std::map<std::string, Assignment> books;
  int made = 0;
  const auto round = [&](double now, int orders, bool apply) {
    RoundInput input;
    input.now = now;
    input.robots = robots;
    for (int k = 0; k < orders; ++k, ++made) {
      input.pending.push_back(MakeOrder("o" + std::to_string(made), picks.at(static_cast<std::size_t>(made * 37) % picks.size()),
                                        drops.at(static_cast<std::size_t>(made * 5) % drops.size()), now));
    }
    const RoundResult result = kept.Run(input);
    RoundRunner fresh = Runner();
    EXPECT_EQ(Dump(result), Dump(fresh.Run(input))) << "round at " << now;
    EXPECT_EQ(result.awards.size(), static_cast<std::size_t>(orders)) << "round at " << now;
    if (!apply) return;
    for (const RoundAward& a : result.awards) {
      RoundRobot& r = *std::find_if(robots.begin(), robots.end(), [&](const RoundRobot& x) { return x.id == a.award.winners[0]; });
      Assignment& book = books[r.id];
      book.robot_id = r.id;
      AppendOrder(book, a.order_id, a.segments[0], a.after_departure[0], book.order_ids.empty(), now);
      r.assignment = std::make_shared<const Assignment>(book);
      r.queue.push_back(*std::find_if(input.pending.begin(), input.pending.end(),
                                      [&](const auto& o) { return o->id == a.order_id; }));
    }
  };
  const auto progress = [&](std::size_t nth, std::uint64_t reached) {  // of the robots with a queue
    std::vector<RoundRobot*> busy;
    for (RoundRobot& r : robots) {
      if (r.has_queue()) busy.push_back(&r);
    }
    ASSERT_LT(nth, busy.size());
    RoundRobot& r = *busy[nth];
    const std::size_t at = FindWaypoint(*r.assignment, reached);
    ASSERT_LT(at, r.assignment->plan.waypoints.size());
    r.last_reached = reached;
    r.start = r.assignment->plan.waypoints[at].point;
  };
  round(0.0, 3, true);
  round(0.1, 1, false);  // awarded, never applied: the winner's kept entry changed
  round(0.2, 1, true);   // the same robots as before, no progress
  progress(0, 2);
  round(0.3, 1, true);
  round(0.4, 0 + 1, false);
  round(0.9, 1, true);   // a later bucket: queues move by whole buckets
  progress(1, 1);
  progress(0, 3);
  round(1.0, 2, true);
  round(1.05, 1, true);
  round(2.75, 2, true);
}

TEST(AllocationRound, AQueueThatCannotBeReplayedIsNamed) {
  const auto& map = *Chu2024();
  const auto parks = PointsOfKind(map, PointKind::kPark);
  RoundRunner runner = Runner("greedy");
  Assignment book;
  book.robot_id = "R1";
  book.order_ids = {"gone"};
  RoundInput input;
  input.robots = {{"R1", parks.at(0), std::make_shared<const Assignment>(book), 0, {nullptr}}};  // its order's view is missing
  input.pending = {MakeOrder("o1", PointsOfKind(map, PointKind::kPick).at(0), PointsOfKind(map, PointKind::kDrop).at(0), 0.0)};
  const RoundResult r = runner.Run(input);
  ASSERT_EQ(r.notes.size(), 1u);
  EXPECT_EQ(r.notes[0], "allocation: queue of R1 replayed up to gone only: the order is not known");
  ASSERT_EQ(r.awards.size(), 1u);  // still bids (as if idle after what could be replayed)
  EXPECT_EQ(r.awards[0].award.winners, std::vector<std::string>{"R1"});
}

}  // namespace
}  // namespace dispatch::engine
