// SqliteStore against a real on-disk file: durability across close/reopen, idempotent and
// conflicting inserts, the state machine and its journal, paging, migrations, bad files,
// WAL readers beside a writer, transactions, injected statement failures, and a random
// operation sequence checked against an in-memory model (leveldb's ModelDB idea).
#include "storage/sqlite_store.h"

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <algorithm>
#include <atomic>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <thread>

#include "storage/migrations.h"
#include "tests/storage/temp_dir.h"

namespace dispatch::storage {
namespace {

using engine::ErrorCode;
using engine::OrderState;
using testing::FastOptions;
using testing::TempDir;

engine::Order MakeOrder(const std::string& id, const std::string& client_id,
                        std::vector<engine::PointId> picks = {3, 7}, engine::PointId drop = 11) {
  engine::Order o;
  o.id = id;
  o.client_id = client_id;
  o.priority = 2;
  o.picks = std::move(picks);
  o.drop = drop;
  o.work_time = 5.0;
  o.created_time = 1.25;
  return o;
}

std::unique_ptr<SqliteStore> OpenOrDie(const std::string& path, SqliteOptions options = {}) {
  auto store = SqliteStore::Open(path, std::move(options));
  if (!store.ok()) ADD_FAILURE() << store.error().message;
  return store.ok() ? std::move(store).value() : nullptr;
}

// Runs one SQL query on its own connection and returns the first column of every row.
std::vector<std::string> RawQuery(const std::string& path, const std::string& sql) {
  sqlite3* db = nullptr;
  std::vector<std::string> rows;
  EXPECT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  sqlite3_stmt* stmt = nullptr;
  EXPECT_EQ(sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt, nullptr), SQLITE_OK)
      << sqlite3_errmsg(db);
  while (stmt != nullptr && sqlite3_step(stmt) == SQLITE_ROW) {
    const auto* text = reinterpret_cast<const char*>(sqlite3_column_text(stmt, 0));
    rows.push_back(text == nullptr ? "NULL" : text);
  }
  sqlite3_finalize(stmt);
  sqlite3_close(db);
  return rows;
}

// Executes SQL on its own connection; returns SQLite's error message or "" on success.
std::string RawExec(const std::string& path, const std::string& sql) {
  sqlite3* db = nullptr;
  EXPECT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  char* message = nullptr;
  const int rc = sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &message);
  std::string out = rc == SQLITE_OK ? "" : (message != nullptr ? message : "error");
  sqlite3_free(message);
  sqlite3_close(db);
  return out;
}

class SqliteStoreTest : public ::testing::Test {
 protected:
  std::string db_path() const { return dir_.File("dispatch.db"); }
  TempDir dir_;
};

TEST_F(SqliteStoreTest, MigratesAnEmptyFileInOrderAndReopenIsIdempotent) {
  const int latest = static_cast<int>(Migrations().size());
  ASSERT_GE(latest, 1);
  for (int i = 0; i < latest; ++i) EXPECT_EQ(Migrations()[static_cast<size_t>(i)].version, i + 1);
  {
    auto store = OpenOrDie(db_path());
    ASSERT_NE(store, nullptr);
    EXPECT_EQ(store->schema_version(), latest);
  }
  std::vector<std::string> expected;
  for (int v = 1; v <= latest; ++v) expected.push_back(std::to_string(v));
  EXPECT_EQ(RawQuery(db_path(), "SELECT version FROM schema_migrations ORDER BY rowid"), expected);
  EXPECT_EQ(RawQuery(db_path(), "PRAGMA journal_mode"), std::vector<std::string>{"wal"});
  for (const char* table : {"orders", "order_events", "robots", "assignments", "map_versions"}) {
    EXPECT_EQ(RawQuery(db_path(), std::string("SELECT count(*) FROM sqlite_master WHERE "
                                              "type = 'table' AND name = '") + table + "'"),
              std::vector<std::string>{"1"})
        << table;
  }
  // Reopening applies nothing twice and keeps data.
  {
    auto store = OpenOrDie(db_path());
    ASSERT_NE(store, nullptr);
    ASSERT_TRUE(store->InsertOrder(MakeOrder("o1", "c1")).ok());
  }
  auto again = OpenOrDie(db_path());
  ASSERT_NE(again, nullptr);
  EXPECT_EQ(again->schema_version(), latest);
  EXPECT_EQ(RawQuery(db_path(), "SELECT version FROM schema_migrations ORDER BY rowid"), expected);
  EXPECT_TRUE(again->GetOrder("o1").ok());
}

TEST_F(SqliteStoreTest, ANewerSchemaIsAClearError) {
  ASSERT_NE(OpenOrDie(db_path()), nullptr);
  const int future = static_cast<int>(Migrations().size()) + 1;
  ASSERT_EQ(RawExec(db_path(), "INSERT INTO schema_migrations (version, name) VALUES (" +
                                   std::to_string(future) + ", 'from the future')"),
            "");
  auto store = SqliteStore::Open(db_path());
  ASSERT_FALSE(store.ok());
  EXPECT_EQ(store.error().code, ErrorCode::kIoError);
  EXPECT_NE(store.error().message.find("newer than this program supports"), std::string::npos)
      << store.error().message;
  EXPECT_NE(store.error().message.find(db_path()), std::string::npos) << store.error().message;
}

TEST_F(SqliteStoreTest, ANonSqliteFileIsAClearErrorAndIsLeftAlone) {
  const std::string garbage(4096, 'x');
  { std::ofstream(db_path(), std::ios::binary) << "this is not a database\n" << garbage; }
  auto store = SqliteStore::Open(db_path());
  ASSERT_FALSE(store.ok());
  EXPECT_EQ(store.error().code, ErrorCode::kIoError);
  EXPECT_NE(store.error().message.find("not a database"), std::string::npos)
      << store.error().message;
  EXPECT_NE(store.error().message.find(db_path()), std::string::npos) << store.error().message;
  std::ifstream in(db_path(), std::ios::binary);
  std::string first_line;
  std::getline(in, first_line);
  EXPECT_EQ(first_line, "this is not a database");
}

TEST_F(SqliteStoreTest, AMissingDirectoryIsAClearError) {
  const std::string path = dir_.File("no/such/dir/dispatch.db");
  auto store = SqliteStore::Open(path);
  ASSERT_FALSE(store.ok());
  EXPECT_EQ(store.error().code, ErrorCode::kIoError);
  EXPECT_NE(store.error().message.find(path), std::string::npos) << store.error().message;
}

TEST_F(SqliteStoreTest, EverythingSurvivesCloseAndReopen) {
  engine::Order formation = MakeOrder("o2", "c2", {4, 5, 6}, 12);
  formation.formation = true;
  formation.priority = -3;
  formation.work_time = 2.75;
  formation.release_time = 40.125;
  formation.created_time = 0.1 + 0.2;  // not exactly representable: must round-trip bit-exact
  engine::Robot robot;
  robot.id = "R7";
  robot.state = engine::RobotState::kMoving;
  robot.pose.position = {19.0, 16.5};
  robot.pose.heading = -1.5707963267948966;
  robot.current_point = 42;
  robot.task_queue = {"o1", "o2"};
  robot.battery = 0.875;
  engine::Plan plan;
  plan.robot_id = "R7";
  plan.waypoints = {{0, 42, {19.0, 16.5}, 10.0, engine::WaypointAction::kMove, 0.0},
                    {1, 43, {20.0, 16.5}, 11.0, engine::WaypointAction::kPick, 5.0},
                    {2, 12, {21.0, 16.5}, 17.0, engine::WaypointAction::kDrop, 5.0}};
  {
    auto store = OpenOrDie(db_path());
    ASSERT_NE(store, nullptr);
    ASSERT_TRUE(store->InsertOrder(MakeOrder("o1", "c1")).ok());
    ASSERT_TRUE(store->InsertOrder(formation).ok());
    ASSERT_TRUE(store->TransitionOrder({"o2", OrderState::kAssigned, 3.0,
                                        std::vector<std::string>{"R7", "R1", "R2"}, "auction"})
                    .ok());
    ASSERT_TRUE(store->AppendProgress("o2", 4.0, "R7 re-planned").ok());
    ASSERT_TRUE(store->UpsertRobot({robot, "differential", 4.5, 17, 18}).ok());
    ASSERT_TRUE(store->SaveAssignment({"R7", 3, {"o2"}, plan, 1, 4.0}).ok());
    ASSERT_TRUE(store->RecordMapVersion({0, "chu2024", "abc123", "builtin:chu2024", 0.0}).ok());
  }
  auto store = OpenOrDie(db_path());
  ASSERT_NE(store, nullptr);

  auto o2 = store->GetOrder("o2");
  ASSERT_TRUE(o2.ok()) << o2.error().message;
  EXPECT_EQ(o2->order.client_id, "c2");
  EXPECT_EQ(o2->order.priority, -3);
  EXPECT_EQ(o2->order.picks, (std::vector<engine::PointId>{4, 5, 6}));
  EXPECT_EQ(o2->order.drop, 12);
  EXPECT_TRUE(o2->order.formation);
  EXPECT_EQ(o2->order.work_time, 2.75);
  EXPECT_EQ(o2->order.release_time, std::optional<double>(40.125));
  EXPECT_EQ(o2->order.created_time, 0.1 + 0.2);
  EXPECT_EQ(o2->order.state, OrderState::kAssigned);
  EXPECT_EQ(o2->robots, (std::vector<std::string>{"R7", "R1", "R2"}));
  EXPECT_EQ(o2->updated_time, 3.0);
  EXPECT_EQ(o2->content_hash, OrderContentHash(formation));
  auto by_client = store->GetOrderByClientId("c1");
  ASSERT_TRUE(by_client.ok());
  EXPECT_EQ(by_client->order.id, "o1");
  EXPECT_FALSE(by_client->order.release_time.has_value());

  auto events = store->ListEvents({"o2", 0, 100});
  ASSERT_TRUE(events.ok());
  ASSERT_EQ(events->size(), 3u);
  EXPECT_EQ((*events)[0].type, OrderEventType::kCreated);
  EXPECT_EQ((*events)[1].type, OrderEventType::kStateChanged);
  EXPECT_EQ((*events)[1].previous_state, OrderState::kAccepted);
  EXPECT_EQ((*events)[1].detail, "auction");
  EXPECT_EQ((*events)[2].type, OrderEventType::kProgress);
  EXPECT_EQ((*events)[2].state, OrderState::kAssigned);
  EXPECT_EQ((*events)[2].robots, (std::vector<std::string>{"R7", "R1", "R2"}));

  auto r = store->GetRobot("R7");
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(r->robot.state, engine::RobotState::kMoving);
  EXPECT_EQ(r->robot.pose.position, robot.pose.position);
  EXPECT_EQ(r->robot.pose.heading, robot.pose.heading);
  EXPECT_EQ(r->robot.current_point, 42);
  EXPECT_EQ(r->robot.task_queue, robot.task_queue);
  EXPECT_EQ(r->robot.battery, robot.battery);
  EXPECT_EQ(r->kind, "differential");
  EXPECT_EQ(r->last_seen, 4.5);
  EXPECT_EQ(r->last_acked_sequence, 17u);
  EXPECT_EQ(r->next_sequence, 18u);

  auto a = store->GetAssignment("R7");
  ASSERT_TRUE(a.ok()) << a.error().message;
  EXPECT_EQ(a->plan_id, 3u);
  EXPECT_EQ(a->order_ids, std::vector<std::string>{"o2"});
  EXPECT_EQ(a->released_up_to, 1);
  EXPECT_EQ(a->plan.robot_id, "R7");
  ASSERT_EQ(a->plan.waypoints.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    const engine::Waypoint& got = a->plan.waypoints[i];
    const engine::Waypoint& want = plan.waypoints[i];
    EXPECT_EQ(got.seq, want.seq);
    EXPECT_EQ(got.point, want.point);
    EXPECT_EQ(got.xy, want.xy);
    EXPECT_EQ(got.eta, want.eta);
    EXPECT_EQ(got.action, want.action);
    EXPECT_EQ(got.dwell, want.dwell);
  }
  auto map = store->LatestMapVersion();
  ASSERT_TRUE(map.ok());
  EXPECT_EQ(map->name, "chu2024");
  EXPECT_EQ(map->source, "builtin:chu2024");
}

TEST_F(SqliteStoreTest, InsertIsIdempotentOnClientId) {
  auto store = OpenOrDie(db_path());
  ASSERT_NE(store, nullptr);
  auto first = store->InsertOrder(MakeOrder("o1", "wms-1"));
  ASSERT_TRUE(first.ok());
  EXPECT_TRUE(first->created);
  // The repeat gets a new server id from the caller, but the same content.
  engine::Order repeat = MakeOrder("o-other", "wms-1");
  repeat.created_time = 99.0;  // not part of the content
  auto second = store->InsertOrder(repeat);
  ASSERT_TRUE(second.ok()) << second.error().message;
  EXPECT_FALSE(second->created);
  EXPECT_EQ(second->record.order.id, "o1");
  EXPECT_EQ(second->record.order.created_time, 1.25);
  EXPECT_EQ(store->GetOrder("o-other").error().code, ErrorCode::kNotFound);
  auto events = store->ListEvents({std::nullopt, 0, 100});
  ASSERT_TRUE(events.ok());
  EXPECT_EQ(events->size(), 1u);
}

TEST_F(SqliteStoreTest, AConflictingDuplicateIsDetected) {
  auto store = OpenOrDie(db_path());
  ASSERT_NE(store, nullptr);
  ASSERT_TRUE(store->InsertOrder(MakeOrder("o1", "wms-1")).ok());
  auto other_picks = store->InsertOrder(MakeOrder("o2", "wms-1", {3, 8}));
  ASSERT_FALSE(other_picks.ok());
  EXPECT_EQ(other_picks.error().code, ErrorCode::kFailedPrecondition);
  EXPECT_NE(other_picks.error().message.find("wms-1"), std::string::npos);
  EXPECT_NE(other_picks.error().message.find("different content"), std::string::npos);
  engine::Order formation = MakeOrder("o3", "wms-1");
  formation.formation = true;
  EXPECT_EQ(store->InsertOrder(formation).error().code, ErrorCode::kFailedPrecondition);
  // The same server id under another client id is a conflict too.
  auto taken = store->InsertOrder(MakeOrder("o1", "wms-2"));
  ASSERT_FALSE(taken.ok());
  EXPECT_EQ(taken.error().code, ErrorCode::kFailedPrecondition);
  EXPECT_NE(taken.error().message.find("already belongs"), std::string::npos);
  // Nothing changed.
  auto page = store->ListOrders({});
  ASSERT_TRUE(page.ok());
  ASSERT_EQ(page->orders.size(), 1u);
  EXPECT_EQ(page->orders[0].order.picks, (std::vector<engine::PointId>{3, 7}));
  EXPECT_EQ(store->ListEvents({}).value().size(), 1u);
}

TEST_F(SqliteStoreTest, RejectsMalformedOrders) {
  auto store = OpenOrDie(db_path());
  ASSERT_NE(store, nullptr);
  EXPECT_EQ(store->InsertOrder(MakeOrder("", "c")).error().code, ErrorCode::kInvalidArgument);
  EXPECT_EQ(store->InsertOrder(MakeOrder("o", "")).error().code, ErrorCode::kInvalidArgument);
  EXPECT_EQ(store->InsertOrder(MakeOrder("o", "c", {})).error().code,
            ErrorCode::kInvalidArgument);
  engine::Order assigned = MakeOrder("o", "c");
  assigned.state = OrderState::kAssigned;
  EXPECT_EQ(store->InsertOrder(assigned).error().code, ErrorCode::kInvalidArgument);
  engine::Order nan = MakeOrder("o", "c");
  nan.release_time = std::nan("");
  EXPECT_EQ(store->InsertOrder(nan).error().code, ErrorCode::kInvalidArgument);
  EXPECT_TRUE(store->ListOrders({}).value().orders.empty());
}

TEST_F(SqliteStoreTest, StateTransitionsFollowTheLifecycleAndAreJournaledInOrder) {
  auto store = OpenOrDie(db_path());
  ASSERT_NE(store, nullptr);
  ASSERT_TRUE(store->InsertOrder(MakeOrder("a", "ca")).ok());
  ASSERT_TRUE(store->InsertOrder(MakeOrder("b", "cb")).ok());
  const std::vector<std::string> team = {"R1"};
  ASSERT_TRUE(store->TransitionOrder({"a", OrderState::kAssigned, 2.0, team, "won"}).ok());
  ASSERT_TRUE(store->TransitionOrder({"b", OrderState::kCancelled, 2.5, {}, "client"}).ok());
  ASSERT_TRUE(store->TransitionOrder({"a", OrderState::kInProgress, 3.0, {}, "picking"}).ok());
  ASSERT_TRUE(store->AppendProgress("a", 3.5, "picked at P1").ok());
  ASSERT_TRUE(store->TransitionOrder({"a", OrderState::kCompleted, 4.0, {}, "dropped"}).ok());

  // Forbidden moves change nothing and journal nothing.
  const size_t journal = store->ListEvents({}).value().size();
  auto back = store->TransitionOrder({"a", OrderState::kAssigned, 5.0, {}, ""});
  ASSERT_FALSE(back.ok());
  EXPECT_EQ(back.error().code, ErrorCode::kFailedPrecondition);
  EXPECT_NE(back.error().message.find("from completed to assigned"), std::string::npos)
      << back.error().message;
  EXPECT_EQ(store->TransitionOrder({"b", OrderState::kCancelled, 5.0, {}, ""}).error().code,
            ErrorCode::kFailedPrecondition);
  EXPECT_EQ(store->TransitionOrder({"zz", OrderState::kAssigned, 5.0, {}, ""}).error().code,
            ErrorCode::kNotFound);
  EXPECT_EQ(store->AppendProgress("zz", 5.0, "").error().code, ErrorCode::kNotFound);
  EXPECT_EQ(store->ListEvents({}).value().size(), journal);

  auto a = store->GetOrder("a").value();
  EXPECT_EQ(a.order.state, OrderState::kCompleted);
  EXPECT_EQ(a.robots, team);  // kept when a transition does not name robots
  auto b = store->GetOrder("b").value();
  EXPECT_EQ(b.order.state, OrderState::kCancelled);
  EXPECT_EQ(b.reason, "client");

  const auto all = store->ListEvents({}).value();
  for (size_t i = 1; i < all.size(); ++i) EXPECT_LT(all[i - 1].id, all[i].id);
  std::vector<std::string> a_states;
  for (const OrderEvent& e : store->ListEvents({"a", 0, 100}).value()) {
    a_states.push_back(std::string(OrderEventTypeName(e.type)) + ":" +
                       engine::OrderStateName(e.state));
  }
  EXPECT_EQ(a_states, (std::vector<std::string>{"created:accepted", "state_changed:assigned",
                                                "state_changed:in_progress", "progress:in_progress",
                                                "state_changed:completed"}));
  // Resuming the journal after an event id returns exactly the later events.
  auto tail = store->ListEvents({std::nullopt, all[2].id, 2}).value();
  ASSERT_EQ(tail.size(), 2u);
  EXPECT_EQ(tail[0].id, all[3].id);
  EXPECT_EQ(tail[1].id, all[4].id);
}

TEST_F(SqliteStoreTest, TheJournalIsAppendOnly) {
  {
    auto store = OpenOrDie(db_path());
    ASSERT_NE(store, nullptr);
    ASSERT_TRUE(store->InsertOrder(MakeOrder("a", "ca")).ok());
  }
  EXPECT_NE(RawExec(db_path(), "UPDATE order_events SET detail = 'x'").find("append-only"),
            std::string::npos);
  EXPECT_NE(RawExec(db_path(), "DELETE FROM order_events").find("append-only"),
            std::string::npos);
  EXPECT_EQ(RawQuery(db_path(), "SELECT detail FROM order_events"),
            std::vector<std::string>{"accepted"});
}

TEST_F(SqliteStoreTest, ListOrdersPagesWithAStateFilter) {
  auto store = OpenOrDie(db_path(), FastOptions());
  ASSERT_NE(store, nullptr);
  for (int i = 0; i < 25; ++i) {
    const std::string id = "o" + std::to_string(i);
    ASSERT_TRUE(store->InsertOrder(MakeOrder(id, "c" + std::to_string(i))).ok());
    if (i % 3 == 0) {
      ASSERT_TRUE(store->TransitionOrder({id, OrderState::kAssigned, 1, {}, ""}).ok());
    }
  }
  std::vector<std::string> seen;
  std::vector<size_t> sizes;
  OrderQuery q;
  q.page_size = 10;
  for (int guard = 0; guard < 10; ++guard) {
    auto page = store->ListOrders(q);
    ASSERT_TRUE(page.ok()) << page.error().message;
    sizes.push_back(page->orders.size());
    for (const OrderRecord& r : page->orders) seen.push_back(r.order.id);
    if (guard == 0) {  // an insert between pages shows up at the end, never twice
      ASSERT_TRUE(store->InsertOrder(MakeOrder("late", "c-late")).ok());
    }
    if (page->next_page_token.empty()) break;
    q.page_token = page->next_page_token;
  }
  EXPECT_EQ(sizes, (std::vector<size_t>{10, 10, 6}));
  ASSERT_EQ(seen.size(), 26u);
  for (int i = 0; i < 25; ++i) EXPECT_EQ(seen[static_cast<size_t>(i)], "o" + std::to_string(i));
  EXPECT_EQ(seen.back(), "late");

  // State filter, across pages.
  OrderQuery assigned;
  assigned.states = {OrderState::kAssigned};
  assigned.page_size = 4;
  std::vector<std::string> got;
  for (int guard = 0; guard < 10; ++guard) {
    auto page = store->ListOrders(assigned).value();
    for (const OrderRecord& r : page.orders) {
      EXPECT_EQ(r.order.state, OrderState::kAssigned);
      got.push_back(r.order.id);
    }
    if (page.next_page_token.empty()) break;
    assigned.page_token = page.next_page_token;
  }
  EXPECT_EQ(got, (std::vector<std::string>{"o0", "o3", "o6", "o9", "o12", "o15", "o18", "o21",
                                           "o24"}));
  OrderQuery two_states;
  two_states.states = {OrderState::kAccepted, OrderState::kAssigned};
  EXPECT_EQ(store->ListOrders(two_states).value().orders.size(), 26u);
  OrderQuery none;
  none.states = {OrderState::kCompleted};
  EXPECT_TRUE(store->ListOrders(none).value().orders.empty());

  for (const char* bad : {"abc", "-1", "12x", " 3"}) {
    OrderQuery q2;
    q2.page_token = bad;
    auto page = store->ListOrders(q2);
    ASSERT_FALSE(page.ok()) << bad;
    EXPECT_EQ(page.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(page.error().message.find(bad), std::string::npos);
  }
  OrderQuery huge;
  huge.page_size = 1 << 30;  // capped, not an error
  EXPECT_EQ(store->ListOrders(huge).value().orders.size(), 26u);
}

TEST_F(SqliteStoreTest, ReadersOnAnotherConnectionAreNotBlockedByAnOpenWrite) {
  auto writer = OpenOrDie(db_path());
  auto reader = OpenOrDie(db_path());
  ASSERT_NE(writer, nullptr);
  ASSERT_NE(reader, nullptr);
  ASSERT_TRUE(writer->InsertOrder(MakeOrder("before", "c0")).ok());
  Status inside = writer->RunInTransaction([&](Store& tx) -> Status {
    auto inserted = tx.InsertOrder(MakeOrder("pending", "c1"));
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
      EXPECT_TRUE(writer->InsertOrder(MakeOrder("o" + n, "c" + n)).ok());
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
  auto failed = store->InsertOrder(MakeOrder("o1", "c1"));
  ASSERT_FALSE(failed.ok());
  EXPECT_EQ(failed.error().code, ErrorCode::kIoError);
  EXPECT_NE(failed.error().message.find("injected: disk full"), std::string::npos);
  EXPECT_NE(failed.error().message.find("o1"), std::string::npos);
  EXPECT_EQ(store->GetOrder("o1").error().code, ErrorCode::kNotFound);
  EXPECT_EQ(store->GetOrderByClientId("c1").error().code, ErrorCode::kNotFound);
  EXPECT_TRUE(store->ListEvents({}).value().empty());

  // The store is still usable; the retry succeeds as a new order.
  fail_on.clear();
  auto retry = store->InsertOrder(MakeOrder("o1", "c1"));
  ASSERT_TRUE(retry.ok()) << retry.error().message;
  EXPECT_TRUE(retry->created);

  // A transition whose journal entry fails does not change the state.
  fail_on = "INSERT INTO order_events";
  EXPECT_FALSE(store->TransitionOrder({"o1", OrderState::kAssigned, 2, std::vector<std::string>{"R1"}, ""}).ok());
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
    if (!tx.InsertOrder(MakeOrder("a", "ca")).ok()) return engine::IoError("unexpected");
    if (!tx.TransitionOrder({"a", OrderState::kAssigned, 1, std::vector<std::string>{"R1"}, ""}).ok()) {
      return engine::IoError("unexpected");
    }
    return engine::InvalidArgument("changed my mind");
  });
  ASSERT_FALSE(aborted.ok());
  EXPECT_EQ(aborted.error().message, "changed my mind");
  EXPECT_EQ(store->GetOrder("a").error().code, ErrorCode::kNotFound);
  EXPECT_TRUE(store->ListEvents({}).value().empty());

  Status nested = store->RunInTransaction([](Store& tx) -> Status {
    if (!tx.InsertOrder(MakeOrder("outer", "c-outer")).ok()) return engine::IoError("x");
    Status inner = tx.RunInTransaction([](Store& tx2) -> Status {
      if (!tx2.InsertOrder(MakeOrder("inner", "c-inner")).ok()) return engine::IoError("x");
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
  ASSERT_TRUE(store->UpsertRobot(r).ok());
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
  EXPECT_EQ(store->GetRobot("R9").error().code, ErrorCode::kNotFound);
  RobotRecord nameless;
  EXPECT_EQ(store->UpsertRobot(nameless).error().code, ErrorCode::kInvalidArgument);

  AssignmentRecord a;
  a.robot_id = "R1";
  a.plan_id = 1;
  a.plan.waypoints = {{0, 1, {0.0, 0.0}, 0.0, engine::WaypointAction::kMove, 0.0}};
  ASSERT_TRUE(store->SaveAssignment(a).ok());
  a.plan_id = 2;
  ASSERT_TRUE(store->SaveAssignment(a).ok());
  EXPECT_EQ(store->GetAssignment("R1")->plan_id, 2u);
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
  auto v1 = store->RecordMapVersion({0, "chu2024", "h1", "builtin", 0.0}).value();
  auto same = store->RecordMapVersion({0, "chu2024", "h1", "builtin", 5.0}).value();
  EXPECT_EQ(same.version, v1.version);
  auto v2 = store->RecordMapVersion({0, "chu2024", "h2", "file.json", 6.0}).value();
  EXPECT_GT(v2.version, v1.version);
  EXPECT_EQ(store->LatestMapVersion()->content_hash, "h2");
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
      auto r = store->InsertOrder(MakeOrder("id-" + client, client, picks));
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
      auto r = store->TransitionOrder({"id-" + client, to, 1.0, {}, ""});
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
}  // namespace dispatch::storage
