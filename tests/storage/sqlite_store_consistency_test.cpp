// SqliteStore against a real on-disk file, under load and failure: WAL readers beside a
// writer, injected statement failures, transactions, robots, assignments and map versions, and
// a random operation sequence checked against an in-memory model (leveldb's ModelDB idea).
#include "storage/sqlite_store.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <map>
#include <random>
#include <set>
#include <thread>

#include "tests/storage/sqlite_test_support.h"

// In the helpers' namespace (sqlite_test_support.h).
namespace dispatch::storage::testing {
namespace {

using engine::ErrorCode;
using engine::OrderState;

TEST_F(SqliteStoreTest, ReadersOnAnotherConnectionAreNotBlockedByAnOpenWrite) {
  auto writer = OpenOrDie(db_path());
  auto reader = OpenOrDie(db_path());
  ASSERT_NE(writer, nullptr);
  ASSERT_NE(reader, nullptr);
  ASSERT_TRUE(writer->InsertOrder(MakeOrder("before", "c0"), "").ok());
  Status inside = writer->RunInTransaction([&](Store& tx) -> Status {
    auto inserted = tx.InsertOrder(MakeOrder("pending", "c1"), "");
    if (!inserted.ok()) return inserted.error();
    // The write lock is held and the insert is uncommitted: the reader neither waits nor
    // sees it (WAL snapshot isolation).
    auto pending = reader->GetOrder("pending");
    EXPECT_FALSE(pending.ok());
    if (!pending.ok()) {
      EXPECT_EQ(pending.error().code, ErrorCode::kNotFound);
    }
    auto page = reader->ListOrders({});
    EXPECT_TRUE(page.ok()) << (page.ok() ? "" : page.error().message);
    if (page.ok()) {
      EXPECT_EQ(page->orders.size(), 1u);
    }
    return engine::Ok{};
  });
  ASSERT_TRUE(inside.ok()) << inside.error().message;
  EXPECT_TRUE(reader->GetOrder("pending").ok());
}

TEST_F(SqliteStoreTest, AConcurrentReaderSeesAGrowingPrefixWhileAThreadWrites) {
  auto writer = OpenOrDie(db_path(), FastOptions());
  auto reader = OpenOrDie(db_path(), FastOptions());
  ASSERT_NE(writer, nullptr);
  ASSERT_NE(reader, nullptr);
  constexpr int kOrders = 150;
  std::atomic<bool> done{false};
  std::thread write_thread([&] {
    for (int i = 0; i < kOrders; ++i) {
      const std::string n = std::to_string(i);
      EXPECT_TRUE(writer->InsertOrder(MakeOrder("o" + n, "c" + n), "").ok());
    }
    done = true;
  });
  size_t last = 0;
  bool finished = false;
  while (!finished) {
    finished = done.load();  // read once more after the writer finished
    OrderQuery q;
    q.page_size = kMaxPageSize;
    auto page = reader->ListOrders(q);
    if (!page.ok()) {  // no ASSERT here: the writer thread must be joined
      ADD_FAILURE() << page.error().message;
      break;
    }
    EXPECT_GE(page->orders.size(), last);  // committed orders never disappear
    for (size_t i = 0; i < page->orders.size(); ++i) {
      EXPECT_EQ(page->orders[i].order.id, "o" + std::to_string(i));  // a prefix, in order
    }
    last = page->orders.size();
  }
  write_thread.join();
  EXPECT_EQ(last, static_cast<size_t>(kOrders));
}

TEST_F(SqliteStoreTest, AFailedStatementLeavesNoPartialOrder) {
  std::string fail_on;  // fail the first data statement whose SQL contains this
  SqliteOptions options;
  options.before_write = [&](std::string_view sql) -> Status {
    if (!fail_on.empty() && sql.find(fail_on) != std::string_view::npos) {
      return engine::IoError("injected: disk full");
    }
    return engine::Ok{};
  };
  auto store = OpenOrDie(db_path(), options);
  ASSERT_NE(store, nullptr);

  // The order row is written, then its first event fails: both must be gone.
  fail_on = "INSERT INTO order_events";
  auto failed = store->InsertOrder(MakeOrder("o1", "c1"), "");
  ASSERT_FALSE(failed.ok());
  EXPECT_EQ(failed.error().code, ErrorCode::kIoError);
  EXPECT_NE(failed.error().message.find("injected: disk full"), std::string::npos);
  EXPECT_NE(failed.error().message.find("o1"), std::string::npos);
  EXPECT_EQ(store->GetOrder("o1").error().code, ErrorCode::kNotFound);
  EXPECT_EQ(store->GetOrderByClientId("c1").error().code, ErrorCode::kNotFound);
  EXPECT_TRUE(store->ListEvents({}).value().empty());

  // The store is still usable; the retry succeeds as a new order.
  fail_on.clear();
  auto retry = store->InsertOrder(MakeOrder("o1", "c1"), "");
  ASSERT_TRUE(retry.ok()) << retry.error().message;
  EXPECT_TRUE(retry->created);

  // A transition whose journal entry fails does not change the state.
  fail_on = "INSERT INTO order_events";
  EXPECT_FALSE(store->TransitionOrder({"o1", OrderState::kAssigned, 2, std::vector<std::string>{"R1"}, "", {}, ""}).ok());
  EXPECT_EQ(store->GetOrder("o1")->order.state, OrderState::kAccepted);
  EXPECT_TRUE(store->GetOrder("o1")->robots.empty());
  EXPECT_EQ(store->ListEvents({}).value().size(), 1u);

  // And it survives a reopen exactly as acknowledged.
  fail_on.clear();
  store.reset();
  auto reopened = OpenOrDie(db_path());
  ASSERT_NE(reopened, nullptr);
  EXPECT_EQ(reopened->GetOrder("o1")->order.state, OrderState::kAccepted);
  EXPECT_EQ(reopened->ListEvents({}).value().size(), 1u);
}

TEST_F(SqliteStoreTest, RunInTransactionIsAllOrNothingAndNests) {
  auto store = OpenOrDie(db_path());
  ASSERT_NE(store, nullptr);
  Status aborted = store->RunInTransaction([](Store& tx) -> Status {
    if (!tx.InsertOrder(MakeOrder("a", "ca"), "").ok()) return engine::IoError("unexpected");
    if (!tx.TransitionOrder({"a", OrderState::kAssigned, 1, std::vector<std::string>{"R1"}, "", {}, ""}).ok()) {
      return engine::IoError("unexpected");
    }
    return engine::InvalidArgument("changed my mind");
  });
  ASSERT_FALSE(aborted.ok());
  EXPECT_EQ(aborted.error().message, "changed my mind");
  EXPECT_EQ(store->GetOrder("a").error().code, ErrorCode::kNotFound);
  EXPECT_TRUE(store->ListEvents({}).value().empty());

  Status nested = store->RunInTransaction([](Store& tx) -> Status {
    if (!tx.InsertOrder(MakeOrder("outer", "c-outer"), "").ok()) return engine::IoError("x");
    Status inner = tx.RunInTransaction([](Store& tx2) -> Status {
      if (!tx2.InsertOrder(MakeOrder("inner", "c-inner"), "").ok()) return engine::IoError("x");
      return engine::IoError("inner failed");
    });
    EXPECT_FALSE(inner.ok());
    return engine::Ok{};  // the outer goes on
  });
  ASSERT_TRUE(nested.ok()) << nested.error().message;
  EXPECT_TRUE(store->GetOrder("outer").ok());
  EXPECT_EQ(store->GetOrder("inner").error().code, ErrorCode::kNotFound);
}

TEST_F(SqliteStoreTest, RobotsAssignmentsAndMapVersions) {
  auto store = OpenOrDie(db_path());
  ASSERT_NE(store, nullptr);
  RobotRecord r;
  r.robot.id = "R2";
  r.robot.kind = engine::RobotKind::kFourWheelSteer;
  ASSERT_TRUE(store->UpsertRobot(r).ok());
  r.robot.kind = engine::RobotKind::kDifferential;
  r.robot.id = "R1";
  ASSERT_TRUE(store->UpsertRobot(r).ok());
  r.robot.state = engine::RobotState::kOffline;
  r.last_acked_sequence = 9;
  ASSERT_TRUE(store->UpsertRobot(r).ok());  // update, not a second row
  auto robots = store->ListRobots().value();
  ASSERT_EQ(robots.size(), 2u);
  EXPECT_EQ(robots[0].robot.id, "R1");
  EXPECT_EQ(robots[0].robot.state, engine::RobotState::kOffline);
  EXPECT_EQ(robots[0].last_acked_sequence, 9u);
  EXPECT_EQ(robots[0].robot.kind, engine::RobotKind::kDifferential);
  EXPECT_EQ(robots[1].robot.kind, engine::RobotKind::kFourWheelSteer);
  EXPECT_EQ(store->GetRobot("R9").error().code, ErrorCode::kNotFound);
  RobotRecord nameless;
  EXPECT_EQ(store->UpsertRobot(nameless).error().code, ErrorCode::kInvalidArgument);

  AssignmentRecord a;
  a.robot_id = "R1";
  a.plan_id = 1;
  a.plan.waypoints = {{0, 1, {0.0, 0.0}, 0.0, engine::WaypointAction::kMove, 0.0, {}, {}}};
  ASSERT_TRUE(store->SaveAssignment(a).ok());
  a.plan_id = 2;
  ASSERT_TRUE(store->SaveAssignment(a).ok());
  EXPECT_EQ(store->GetAssignment("R1")->plan_id, 2u);
  // A four-wheel-steer robot's poses in a free space keep their heading and mode.
  a.plan.waypoints.push_back({1, 1, {0.5, 0.2}, 1.0, engine::WaypointAction::kMove, 0.0, 0.25,
                              engine::MotionMode::kCrabLeft});
  a.plan.waypoints.push_back({2, 1, {0.5, 0.2}, 2.0, engine::WaypointAction::kMove, 0.0, 1.5, std::nullopt});
  ASSERT_TRUE(store->SaveAssignment(a).ok());
  const auto posed = store->GetAssignment("R1")->plan.waypoints;
  ASSERT_EQ(posed.size(), 3u);
  EXPECT_FALSE(posed[0].heading.has_value());
  EXPECT_FALSE(posed[0].mode.has_value());
  EXPECT_EQ(posed[1].heading, 0.25);
  EXPECT_EQ(posed[1].mode, engine::MotionMode::kCrabLeft);
  EXPECT_EQ(posed[2].heading, 1.5);
  EXPECT_FALSE(posed[2].mode.has_value());
  a.plan.waypoints.resize(1);
  EXPECT_EQ(store->ListAssignments().value().size(), 1u);
  a.plan.robot_id = "R2";
  EXPECT_EQ(store->SaveAssignment(a).error().code, ErrorCode::kInvalidArgument);
  a.plan.robot_id.clear();
  a.plan.waypoints[0].eta = std::numeric_limits<double>::infinity();
  EXPECT_EQ(store->SaveAssignment(a).error().code, ErrorCode::kInvalidArgument);
  ASSERT_TRUE(store->DeleteAssignment("R1").ok());
  EXPECT_EQ(store->DeleteAssignment("R1").error().code, ErrorCode::kNotFound);
  EXPECT_TRUE(store->ListAssignments().value().empty());

  EXPECT_EQ(store->LatestMapVersion().error().code, ErrorCode::kNotFound);
  auto v1 = store->RecordMapVersion({0, "chu2024", "h1", "builtin", 0.0, {}}).value();
  auto same = store->RecordMapVersion({0, "chu2024", "h1", "builtin", 5.0, {}}).value();
  EXPECT_EQ(same.version, v1.version);
  auto v2 = store->RecordMapVersion({0, "chu2024", "h2", "file.json", 6.0, {}}).value();
  EXPECT_GT(v2.version, v1.version);
  EXPECT_EQ(store->LatestMapVersion()->content_hash, "h2");
  // The same map under a new hash function: re-tagged, no new version; an older version's
  // hash, or another map's, is not the same map.
  MapVersion renamed{0, "chu2024", "h2-new", "builtin", 7.0, {"h0", "h2"}};
  auto retagged = store->RecordMapVersion(renamed).value();
  EXPECT_EQ(retagged.version, v2.version);
  EXPECT_EQ(retagged.content_hash, "h2-new");
  EXPECT_EQ(store->LatestMapVersion()->content_hash, "h2-new");
  EXPECT_EQ(store->LatestMapVersion()->version, v2.version);
  auto other = store->RecordMapVersion({0, "chu2024", "h3", "builtin", 8.0, {"h1"}}).value();
  EXPECT_GT(other.version, v2.version);
  auto another_map = store->RecordMapVersion({0, "grid", "g-new", "grid.map", 9.0, {"h3"}}).value();
  EXPECT_GT(another_map.version, other.version);
}

// Random operations against SqliteStore and an in-memory model of its contract.
TEST_F(SqliteStoreTest, RandomOperationsMatchAnInMemoryModel) {
  auto store = OpenOrDie(db_path(), FastOptions());
  ASSERT_NE(store, nullptr);
  struct ModelOrder {
    std::vector<engine::PointId> picks;
    OrderState state;
    int events;
  };
  std::map<std::string, ModelOrder> model;  // by client id; server id = "id-" + client id
  std::vector<std::string> insertion_order;
  std::mt19937 rng(20240531);
  const std::vector<OrderState> states = {OrderState::kAccepted,  OrderState::kAssigned,
                                          OrderState::kInProgress, OrderState::kCompleted,
                                          OrderState::kCancelled, OrderState::kFailed};
  int total_events = 0;
  for (int step = 0; step < 400; ++step) {
    const int op = static_cast<int>(rng() % 3);
    const std::string client = "c" + std::to_string(rng() % 40);
    const std::vector<engine::PointId> picks = {static_cast<engine::PointId>(rng() % 3)};
    const auto it = model.find(client);
    if (op == 0) {
      auto r = store->InsertOrder(MakeOrder("id-" + client, client, picks), "");
      if (it == model.end()) {
        ASSERT_TRUE(r.ok()) << r.error().message;
        EXPECT_TRUE(r->created);
        model[client] = {picks, OrderState::kAccepted, 1};
        insertion_order.push_back(client);
        ++total_events;
      } else if (it->second.picks == picks) {
        ASSERT_TRUE(r.ok());
        EXPECT_FALSE(r->created);
        EXPECT_EQ(r->record.order.state, it->second.state);
      } else {
        ASSERT_FALSE(r.ok());
        EXPECT_EQ(r.error().code, ErrorCode::kFailedPrecondition);
      }
    } else if (op == 1) {
      const OrderState to = states[rng() % states.size()];
      auto r = store->TransitionOrder({"id-" + client, to, 1.0, {}, "", {}, ""});
      if (it == model.end()) {
        EXPECT_EQ(r.error().code, ErrorCode::kNotFound);
      } else if (engine::CanTransition(it->second.state, to)) {
        ASSERT_TRUE(r.ok()) << r.error().message;
        it->second.state = to;
        ++it->second.events;
        ++total_events;
      } else {
        EXPECT_EQ(r.error().code, ErrorCode::kFailedPrecondition);
      }
    } else {
      OrderQuery q;
      q.states = {states[rng() % states.size()]};
      q.page_size = 1 + static_cast<int>(rng() % 7);
      std::vector<std::string> got;
      for (int guard = 0; guard < 100; ++guard) {
        auto page = store->ListOrders(q);
        ASSERT_TRUE(page.ok());
        for (const OrderRecord& rec : page->orders) got.push_back(rec.order.client_id);
        if (page->next_page_token.empty()) break;
        q.page_token = page->next_page_token;
      }
      std::vector<std::string> want;
      for (const std::string& c : insertion_order) {
        if (model[c].state == q.states[0]) want.push_back(c);
      }
      EXPECT_EQ(got, want);
    }
  }
  store.reset();
  auto reopened = OpenOrDie(db_path());
  ASSERT_NE(reopened, nullptr);
  EventQuery all;
  all.limit = 100000;
  EXPECT_EQ(reopened->ListEvents(all).value().size(), static_cast<size_t>(total_events));
  for (const auto& [client, m] : model) {
    auto r = reopened->GetOrderByClientId(client);
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(r->order.state, m.state) << client;
    EXPECT_EQ(r->order.picks, m.picks) << client;
    EXPECT_EQ(reopened->ListEvents({"id-" + client, 0, 1000}).value().size(),
              static_cast<size_t>(m.events));
  }
}

}  // namespace
}  // namespace dispatch::storage::testing
