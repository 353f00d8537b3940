// The dispatcher's parts on their own: robot sessions and what a Hello makes of a robot's
// record (server/robot_sessions.h), the core journal's writer (server/core_journal_writer.h),
// and what a core change stores (server/change_store.h).
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "engine/map/chu2024_floor.h"
#include "engine/routing/route_table.h"
#include "server/change_store.h"
#include "server/core_journal_writer.h"
#include "server/restart_wait.h"
#include "server/robot_sessions.h"
#include "storage/sqlite_store.h"
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

std::unique_ptr<engine::JournaledCore> RecordingCore() {
  auto built = engine::BuildChu2024Floor();
  if (!built.ok()) throw std::runtime_error(built.error().message);
  auto map = std::make_shared<const engine::WarehouseMap>(std::move(built).value());
  auto routes = engine::MakeRouteTable(map, {});
  if (!routes.ok()) throw std::runtime_error(routes.error().message);
  auto core = engine::DispatchCore::Create(map, std::move(routes).value(), {});
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
  auto inserted = (*store)->InsertOrder(order);
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

}  // namespace
}  // namespace dispatch::server
