// The dispatcher's parts on their own: robot sessions and what a Hello makes of a robot's
// record (server/robot_sessions.h), the core journal's writer (server/core_journal_writer.h),
// what a core change stores (server/change_store.h), the round worker (round_worker.h) and
// recovery at start-up (state_recovery.h). The loop's timing and batching parts are in
// loop_pacing_test.cpp.
#include <gtest/gtest.h>

#include <future>
#include <memory>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "engine/dispatch/strategy.h"
#include "server/change_store.h"
#include "server/core_journal_writer.h"
#include "server/explanation.h"
#include "server/json_convert.h"
#include "server/restart_wait.h"
#include "server/robot_sessions.h"
#include "server/round_worker.h"
#include "server/state_recovery.h"
#include "storage/sqlite_store.h"
#include "tests/engine/dispatch/dispatch_test_support.h"
#include "tests/server/test_support.h"

namespace dispatch::server {
namespace {

using testing::TempDir;

class NullLink final : public RobotLink {
 public:
  void Send(RobotOutbound) override {}
  void Close(ServiceStatus) override {}
};

TEST(RobotSessionsTest, AStreamBelongsToItsRobotUntilDetachedOrForgotten) {
  RobotSessions sessions;
  auto first = std::make_shared<NullLink>();
  auto second = std::make_shared<NullLink>();
  EXPECT_EQ(sessions.RobotOf(first.get()), nullptr);
  sessions.Attach("R1", first);
  ASSERT_NE(sessions.RobotOf(first.get()), nullptr);
  EXPECT_EQ(*sessions.RobotOf(first.get()), "R1");
  ASSERT_NE(sessions.Find("R1"), nullptr);
  EXPECT_EQ(sessions.Find("R1")->link, first);
  // A new stream for R1: the old one is detached (handed back to be closed) first.
  EXPECT_EQ(sessions.Detach("R1"), first);
  EXPECT_EQ(sessions.RobotOf(first.get()), nullptr);
  EXPECT_EQ(sessions.Find("R1")->link, nullptr);
  EXPECT_EQ(sessions.Detach("R1"), nullptr);  // nothing left to take
  sessions.Attach("R1", second);
  sessions.Forget(second.get());  // the stream ended
  EXPECT_EQ(sessions.RobotOf(second.get()), nullptr);
  EXPECT_EQ(sessions.Find("R2"), nullptr);
  EXPECT_EQ(sessions.size(), 1u);
}

TEST(RobotSessionsTest, AHelloContinuesTheMessageSequenceAfterWhatTheRobotAcknowledged) {
  storage::RobotRecord known;
  known.robot.id = "R1";
  known.robot.battery = 7.0;  // stored by an older server
  known.next_sequence = 5;
  known.last_acked_sequence = 3;
  known.marks = {"op-1", "op-2", true};  // paused, out of service, cleared off the floor
  RobotInbound hello;
  hello.robot_id = "R1";
  hello.pose.position = {1.0, 2.0};
  hello.last_acked_sequence = 9;  // it heard more than the record knows
  const storage::RobotRecord r = HelloRecord(known, hello, 4, 1.5, 12.0);
  EXPECT_EQ(r.last_acked_sequence, 9u);
  EXPECT_EQ(r.next_sequence, 10u);
  EXPECT_EQ(r.robot.current_point, 4);
  EXPECT_EQ(r.robot.state, engine::RobotState::kIdle);
  EXPECT_EQ(r.robot.max_speed, 1.5);  // it stated none: the allocation's speed
  EXPECT_FALSE(r.robot.battery.has_value());
  EXPECT_EQ(r.kind, "differential");
  EXPECT_EQ(r.last_seen, 12.0);
  EXPECT_EQ(r.marks, (engine::OperatorMarks{"op-1", "op-2", false})) << "back on the floor, still held";
  hello.last_acked_sequence = 1;
  hello.max_speed = 0.8;
  hello.robot_kind = "four_wheel_steer";
  const storage::RobotRecord again = HelloRecord(r, hello, 4, 1.5, 13.0);
  EXPECT_EQ(again.last_acked_sequence, 9u);  // never goes back
  EXPECT_EQ(again.next_sequence, 10u);
  EXPECT_EQ(again.robot.max_speed, 0.8);
  EXPECT_EQ(again.kind, "four_wheel_steer");
}

TEST(RestartWaitTest, EndsWithTheLastAwaitedReportOrAtItsDeadline) {
  using Clock = RestartWait::Clock;
  const Clock::time_point t0{};
  RestartWait wait;
  EXPECT_FALSE(wait.waiting());
  EXPECT_FALSE(wait.Expired(t0 + std::chrono::hours(1)));  // nobody awaited: nothing to expire
  wait.Await("R7");
  wait.Await("R3");
  wait.SetDeadline(t0 + std::chrono::seconds(5));
  EXPECT_EQ(wait.List(), "R3, R7");
  EXPECT_FALSE(wait.Reported("R9"));  // not awaited
  EXPECT_FALSE(wait.Reported("R3"));  // R7 still away
  EXPECT_FALSE(wait.Reported("R3"));  // twice changes nothing
  EXPECT_FALSE(wait.Expired(t0 + std::chrono::seconds(4)));
  EXPECT_TRUE(wait.Expired(t0 + std::chrono::seconds(5)));
  EXPECT_TRUE(wait.Reported("R7"));  // the last one: over
  EXPECT_FALSE(wait.waiting());
  wait.Await("R1");
  wait.End();
  EXPECT_FALSE(wait.waiting());
  EXPECT_EQ(wait.List(), "");
}

using engine::testing_util::Chu2024;
using engine::testing_util::Chu2024Routes;
using engine::testing_util::PointsOfKind;

// A dispatch core on the Chu2024 floor (with traffic control) that journals every call.
std::unique_ptr<engine::JournaledCore> RecordingCore() {
  auto core = engine::DispatchCore::Create(Chu2024(), Chu2024Routes(), {});
  if (!core.ok()) throw std::runtime_error(core.error().message);
  return std::make_unique<engine::JournaledCore>(std::move(core).value(), true);
}

engine::Order Order(const std::string& id) {
  engine::Order o;
  o.id = id;
  o.client_id = id;
  o.picks = {1};
  o.drop = 2;
  return o;
}

TEST(CoreJournalWriterTest, WritesEveryBatchInOrderAndStopsForGoodAtItsLimit) {
  TempDir dir;
  auto journal = storage::JournalStore::Open(dir.File("journal.db"));
  ASSERT_TRUE(journal.ok()) << journal.error().message;
  auto run = (*journal)->StartRun(0.0, "{}", 3);
  ASSERT_TRUE(run.ok());
  auto core = RecordingCore();
  {
    CoreJournalWriter writer(**journal, *run, /*max_bytes=*/0, 0);
    core->AddOrder(Order("o1"));
    writer.Write(*core);
    core->AddOrder(Order("o2"));
    core->AddOrder(Order("o3"));
    writer.Write(*core);
    writer.Write(*core);  // nothing new: nothing written
    writer.Stop();
  }
  auto entries = (*journal)->Read(*run, 0, 100);
  ASSERT_TRUE(entries.ok());
  ASSERT_EQ(entries->size(), 3u);
  for (std::size_t i = 0; i < entries->size(); ++i) EXPECT_EQ((*entries)[i].seq, i + 1);
  auto runs = (*journal)->Runs();
  ASSERT_TRUE(runs.ok());
  EXPECT_FALSE(runs->back().truncated);

  auto limited = (*journal)->StartRun(1.0, "{}", 3);
  ASSERT_TRUE(limited.ok());
  auto second = RecordingCore();
  CoreJournalWriter writer(**journal, *limited, /*max_bytes=*/1, 0);
  second->AddOrder(Order("o1"));
  writer.Write(*second);
  writer.Stop();  // the first batch is written; it passes the limit
  second->AddOrder(Order("o2"));
  writer.Write(*second);  // at the limit: this batch is the last one written, the run is marked
  second->AddOrder(Order("o3"));
  writer.Write(*second);  // not recorded any more
  auto kept = (*journal)->Read(*limited, 0, 100);
  ASSERT_TRUE(kept.ok());
  EXPECT_EQ(kept->size(), 2u);
  runs = (*journal)->Runs();
  ASSERT_TRUE(runs.ok());
  for (const auto& r : *runs) {
    if (r.run == *limited) {
      EXPECT_TRUE(r.truncated);
    }
  }
}

TEST(ChangeStoreTest, AChangeIsStoredWholeOrNotAtAll) {
  TempDir dir;
  auto store = storage::SqliteStore::Open(dir.File("store.db"));
  ASSERT_TRUE(store.ok()) << store.error().message;
  engine::Order order = Order("ord-000001");
  auto inserted = (*store)->InsertOrder(order, "");
  ASSERT_TRUE(inserted.ok()) << inserted.error().message;
  auto record_of = [](const std::string& id) {
    storage::RobotRecord r;
    r.robot.id = id;
    r.next_sequence = 4;
    return r;
  };
  engine::Change change;
  change.time = 3.0;
  engine::OrderChange line;
  line.order_id = order.id;
  line.to = engine::OrderState::kAssigned;
  line.robots = std::vector<std::string>{"R1"};
  line.detail = "won the auction";
  line.award = 0;
  change.orders.push_back(line);
  engine::Assignment plan;
  plan.robot_id = "R1";
  plan.plan.robot_id = "R1";
  plan.order_ids = {order.id};
  change.plans["R1"] = plan;
  const std::vector<std::string> details{"{\"award\": 1}"};
  auto events = StoreChange(**store, change, &details, record_of);
  ASSERT_TRUE(events.ok()) << events.error().message;
  ASSERT_EQ(events->size(), 2u);  // the transition, then the award's explanation
  auto stored = (*store)->GetOrder(order.id);
  ASSERT_TRUE(stored.ok());
  EXPECT_EQ(stored->order.state, engine::OrderState::kAssigned);
  auto robots = (*store)->ListRobots();
  ASSERT_TRUE(robots.ok());
  ASSERT_EQ(robots->size(), 1u);
  EXPECT_EQ(robots->front().robot.task_queue, std::vector<std::string>{order.id});

  // A line for an order the store does not have: the transaction fails, nothing is written.
  engine::Change bad = change;
  bad.orders.front().to = engine::OrderState::kInProgress;
  bad.orders.push_back(line);
  bad.orders.back().order_id = "ord-missing";
  bad.plans["R1"].order_ids = {order.id, "ord-missing"};
  EXPECT_FALSE(StoreChange(**store, bad, nullptr, record_of).ok());
  stored = (*store)->GetOrder(order.id);
  ASSERT_TRUE(stored.ok());
  EXPECT_EQ(stored->order.state, engine::OrderState::kAssigned);
  robots = (*store)->ListRobots();
  ASSERT_TRUE(robots.ok());
  EXPECT_EQ(robots->front().robot.task_queue, std::vector<std::string>{order.id});
}

TEST(RobotSessionsTest, AHoldIsTimedUntilTheGrantOrResumeThatEndsIt) {
  using Kind = RobotOutbound::Kind;
  RobotSession s;
  EXPECT_FALSE(TrackHold(s, Kind::kGrant, 1.0).has_value());  // not held
  EXPECT_FALSE(TrackHold(s, Kind::kHold, 2.0).has_value());
  EXPECT_FALSE(TrackHold(s, Kind::kHold, 3.0).has_value());  // the first Hold counts
  EXPECT_FALSE(TrackHold(s, Kind::kAssignment, 4.0).has_value());
  ASSERT_TRUE(s.held_since.has_value());
  const std::optional<double> waited = TrackHold(s, Kind::kGrant, 5.5);
  ASSERT_TRUE(waited.has_value());
  EXPECT_DOUBLE_EQ(*waited, 3.5);
  EXPECT_FALSE(s.held_since.has_value());
  TrackHold(s, Kind::kHold, 6.0);
  EXPECT_DOUBLE_EQ(TrackHold(s, Kind::kResume, 7.0).value_or(-1.0), 1.0);
}

engine::Bid BidOf(const std::string& robot, double value) {
  engine::Bid bid;
  bid.robot = robot;
  bid.bid = value;
  return bid;
}

TEST(RoundWorkerTest, ARecordedRoundKeepsTheBestBidsForTheExplanationAndNoneForTheCore) {
  engine::RoundResult result;
  engine::RoundAward award;
  award.order_id = "o1";
  award.award.order_id = "o1";
  award.award.winners = {"R40"};
  for (int i = 1; i <= 40; ++i) award.award.bids.push_back(BidOf("R" + std::to_string(i), 100.0 - i));
  award.seconds = 0.5;
  result.awards.push_back(award);
  engine::AllocationConfig config;
  const ServerRound round = RecordRound(result, config, 12.0);
  ASSERT_EQ(round.commit.awards.size(), 1u);
  EXPECT_TRUE(round.commit.awards[0].award.bids.empty());
  EXPECT_EQ(round.commit.awards[0].award.winners, std::vector<std::string>{"R40"});
  EXPECT_EQ(round.commit.awards[0].seconds, 0.5);
  ASSERT_EQ(round.records.size(), 1u);
  EXPECT_EQ(round.records[0].award.bids.size(), kExplainedBids);
  EXPECT_EQ(round.records[0].bids_total, 40u);
  EXPECT_EQ(round.records[0].time, 12.0);
  EXPECT_EQ(round.records[0].alpha, config.alpha);
  ASSERT_EQ(round.details.size(), 1u);
  EXPECT_EQ(round.details[0], AllocationDetail(round.records[0]));
}

TEST(RoundWorkerTest, RunsARoundOffTheCallersThreadAndHandsBackRoundsAfterStopCancelled) {
  const auto& map = *Chu2024();
  auto allocator = engine::MakeAllocator("auction");
  ASSERT_TRUE(allocator.ok());
  engine::AllocationConfig config;
  RoundWorker worker(std::make_unique<engine::RoundRunner>(Chu2024(), Chu2024Routes(), config,
                                                           std::move(allocator).value()),
                     config, 0);
  engine::RoundInput input;
  input.now = 7.0;
  input.robots.push_back({"R1", PointsOfKind(map, engine::PointKind::kPark).at(0), {}, 0, {}});
  auto order = std::make_shared<engine::Order>(Order("o1"));
  order->picks = {PointsOfKind(map, engine::PointKind::kPick).at(3)};
  order->drop = PointsOfKind(map, engine::PointKind::kDrop).at(0);
  input.pending = {order};
  engine::RoundCommit keys;
  keys.origin = 9;
  keys.keys["R1"].plan_id = 4;
  struct Handed {
    std::shared_ptr<ServerRound> round;
    bool cancelled;
    std::thread::id thread;
  };
  std::promise<Handed> handed;
  worker.Run(input, keys, [&handed](std::shared_ptr<ServerRound> round, bool cancelled) {
    handed.set_value({std::move(round), cancelled, std::this_thread::get_id()});
  });
  const Handed got = handed.get_future().get();
  EXPECT_FALSE(got.cancelled);
  EXPECT_NE(got.thread, std::this_thread::get_id());
  ASSERT_EQ(got.round->commit.awards.size(), 1u);
  EXPECT_EQ(got.round->commit.awards[0].award.winners, std::vector<std::string>{"R1"});
  EXPECT_EQ(got.round->records.size(), 1u);
  EXPECT_EQ(got.round->commit.origin, 9u);
  EXPECT_EQ(got.round->commit.keys.at("R1").plan_id, 4u);
  // After Stop: handed back at once, on this thread, cancelled, with its keys and no awards.
  worker.Stop();
  bool ran = false;
  worker.Run(input, keys, [&ran](std::shared_ptr<ServerRound> round, bool cancelled) {
    ran = true;
    EXPECT_TRUE(cancelled);
    EXPECT_TRUE(round->commit.awards.empty());
    EXPECT_EQ(round->commit.origin, 9u);
  });
  EXPECT_TRUE(ran);
}

storage::RobotRecord StoredRobot(const std::string& id, engine::RobotState state, engine::PointId point,
                                 double last_seen) {
  storage::RobotRecord r;
  r.robot.id = id;
  r.robot.state = state;
  r.robot.current_point = point;
  r.robot.pose.position = Chu2024()->point(point).position;
  r.kind = "differential";
  r.last_seen = last_seen;
  r.last_acked_sequence = 10;
  r.next_sequence = 12;
  return r;
}

TEST(StateRecoveryTest, RobotsComeBackOfflineWithTheirPlansAndThoseThatWereOnLineAreAwaited) {
  TempDir dir;
  auto store = storage::SqliteStore::Open(dir.File("store.db"));
  ASSERT_TRUE(store.ok()) << store.error().message;
  ASSERT_TRUE((*store)->InsertOrder(Order("ord-000003"), "").ok());
  ASSERT_TRUE((*store)->InsertOrder(Order("ord-000007"), "").ok());
  storage::OrderTransition cancel;
  cancel.order_id = "ord-000003";
  cancel.to = engine::OrderState::kCancelled;
  cancel.time = 9.0;
  cancel.detail = "cancelled by client";
  ASSERT_TRUE((*store)->TransitionOrder(cancel).ok());
  const auto parks = PointsOfKind(*Chu2024(), engine::PointKind::kPark);
  ASSERT_TRUE((*store)->UpsertRobot(StoredRobot("R1", engine::RobotState::kIdle, parks.at(0), 30.0)).ok());
  ASSERT_TRUE((*store)->UpsertRobot(StoredRobot("R2", engine::RobotState::kOffline, parks.at(6), 5.0)).ok());
  engine::Assignment plan;
  plan.robot_id = "R1";
  plan.plan.robot_id = "R1";
  plan.order_ids = {"ord-000007"};
  plan.updated_time = 42.0;
  ASSERT_TRUE((*store)->SaveAssignment(plan).ok());

  auto core = RecordingCore();
  OrderViews book(10);
  RobotSessions sessions;
  RestartWait wait;
  auto recovered = RecoverState(**store, /*traffic_control=*/true, book, *core, sessions, wait);
  ASSERT_TRUE(recovered.ok()) << recovered.error().message;
  EXPECT_EQ(recovered->latest_time, 42.0);  // the plan's update is the latest time stored
  EXPECT_EQ(recovered->last_order_number, 7);
  EXPECT_EQ(book.all().size(), 2u);
  EXPECT_NE(core->order("ord-000007"), nullptr);
  EXPECT_EQ(core->order("ord-000003"), nullptr);  // finished: in the views only
  EXPECT_EQ(wait.awaited(), std::set<std::string>{"R1"});  // R2 was offline already
  const engine::BookRobot* r1 = core->robot("R1");
  ASSERT_NE(r1, nullptr);
  EXPECT_EQ(r1->robot.state, engine::RobotState::kOffline);
  EXPECT_TRUE(r1->has_assignment);
  EXPECT_EQ(r1->robot.task_queue, std::vector<std::string>{"ord-000007"});
  ASSERT_NE(core->robot("R2"), nullptr);
  EXPECT_FALSE(core->robot("R2")->has_assignment);
  const RobotSession* s1 = sessions.Find("R1");
  ASSERT_NE(s1, nullptr);
  EXPECT_EQ(s1->next_sequence, 12u);
  EXPECT_EQ(s1->last_acked_sequence, 10u);
  EXPECT_TRUE(s1->offline_since.has_value());
  EXPECT_EQ(s1->link, nullptr);

  // Without traffic control nobody is awaited.
  auto plain = RecordingCore();
  OrderViews plain_book(10);
  RobotSessions plain_sessions;
  RestartWait no_wait;
  ASSERT_TRUE(RecoverState(**store, false, plain_book, *plain, plain_sessions, no_wait).ok());
  EXPECT_FALSE(no_wait.waiting());
  EXPECT_EQ(plain_sessions.size(), 2u);
}

TEST(StateRecoveryTest, AnEmptyStoreRecoversNothingAtTimeZero) {
  TempDir dir;
  auto store = storage::SqliteStore::Open(dir.File("store.db"));
  ASSERT_TRUE(store.ok()) << store.error().message;
  auto core = RecordingCore();
  OrderViews book(10);
  RobotSessions sessions;
  RestartWait wait;
  auto recovered = RecoverState(**store, true, book, *core, sessions, wait);
  ASSERT_TRUE(recovered.ok()) << recovered.error().message;
  EXPECT_EQ(recovered->latest_time, 0.0);
  EXPECT_EQ(recovered->last_order_number, 0);
  EXPECT_TRUE(book.all().empty());
  EXPECT_EQ(sessions.size(), 0u);
  EXPECT_FALSE(wait.waiting());
}

}  // namespace
}  // namespace dispatch::server
