// SqliteStore against a real on-disk file: migrations and bad files, durability across
// close/reopen, idempotent and conflicting inserts, the state machine and its journal, paging.
// (Readers beside a writer, failures, transactions, robots and the model check:
// sqlite_store_consistency_test.cpp.)
#include "storage/sqlite_store.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>

#include "storage/migrations.h"
#include "tests/storage/sqlite_test_support.h"

// In the helpers' namespace (sqlite_test_support.h).
namespace dispatch::storage::testing {
namespace {

using engine::ErrorCode;
using engine::OrderState;

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
    ASSERT_TRUE(store->InsertOrder(MakeOrder("o1", "c1"), "").ok());
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
  plan.waypoints = {{0, 42, {19.0, 16.5}, 10.0, engine::WaypointAction::kMove, 0.0, {}, {}},
                    {1, 43, {20.0, 16.5}, 11.0, engine::WaypointAction::kPick, 5.0, {}, {}},
                    {2, 12, {21.0, 16.5}, 17.0, engine::WaypointAction::kDrop, 5.0, {}, {}}};
  {
    auto store = OpenOrDie(db_path());
    ASSERT_NE(store, nullptr);
    ASSERT_TRUE(store->InsertOrder(MakeOrder("o1", "c1"), "").ok());
    ASSERT_TRUE(store->InsertOrder(formation, "").ok());
    ASSERT_TRUE(store->TransitionOrder({"o2", OrderState::kAssigned, 3.0,
                                        std::vector<std::string>{"R7", "R1", "R2"}, "auction", {}, ""})
                    .ok());
    ASSERT_TRUE(store->AppendProgress("o2", 4.0, "R7 re-planned").ok());
    ASSERT_TRUE(store->UpsertRobot({robot, "differential", 4.5, 17, 18, {"op-1", "op-2", false}}).ok());
    ASSERT_TRUE(store->SaveAssignment({"R7", 3, {"o2"}, plan, 1, 4.0}).ok());
    ASSERT_TRUE(store->RecordMapVersion({0, "chu2024", "abc123", "builtin:chu2024", 0.0, {}}).ok());
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
  EXPECT_EQ(r->marks, (engine::OperatorMarks{"op-1", "op-2", false}));

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
  auto first = store->InsertOrder(MakeOrder("o1", "wms-1"), "");
  ASSERT_TRUE(first.ok());
  EXPECT_TRUE(first->created);
  // The repeat gets a new server id from the caller, but the same content.
  engine::Order repeat = MakeOrder("o-other", "wms-1");
  repeat.created_time = 99.0;  // not part of the content
  auto second = store->InsertOrder(repeat, "");
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
  ASSERT_TRUE(store->InsertOrder(MakeOrder("o1", "wms-1"), "").ok());
  auto other_picks = store->InsertOrder(MakeOrder("o2", "wms-1", {3, 8}), "");
  ASSERT_FALSE(other_picks.ok());
  EXPECT_EQ(other_picks.error().code, ErrorCode::kFailedPrecondition);
  EXPECT_NE(other_picks.error().message.find("wms-1"), std::string::npos);
  EXPECT_NE(other_picks.error().message.find("different content"), std::string::npos);
  engine::Order formation = MakeOrder("o3", "wms-1");
  formation.formation = true;
  EXPECT_EQ(store->InsertOrder(formation, "").error().code, ErrorCode::kFailedPrecondition);
  // The same server id under another client id is a conflict too.
  auto taken = store->InsertOrder(MakeOrder("o1", "wms-2"), "");
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
  EXPECT_EQ(store->InsertOrder(MakeOrder("", "c"), "").error().code, ErrorCode::kInvalidArgument);
  EXPECT_EQ(store->InsertOrder(MakeOrder("o", ""), "").error().code, ErrorCode::kInvalidArgument);
  EXPECT_EQ(store->InsertOrder(MakeOrder("o", "c", {}), "").error().code,
            ErrorCode::kInvalidArgument);
  engine::Order assigned = MakeOrder("o", "c");
  assigned.state = OrderState::kAssigned;
  EXPECT_EQ(store->InsertOrder(assigned, "").error().code, ErrorCode::kInvalidArgument);
  engine::Order nan = MakeOrder("o", "c");
  nan.release_time = std::nan("");
  EXPECT_EQ(store->InsertOrder(nan, "").error().code, ErrorCode::kInvalidArgument);
  engine::Order nan_heading = MakeOrder("o", "c");
  nan_heading.stop_headings[0] = std::nan("");
  EXPECT_EQ(store->InsertOrder(nan_heading, "").error().code, ErrorCode::kInvalidArgument);
  EXPECT_TRUE(store->ListOrders({}).value().orders.empty());
}

// Issue 17 §3: the headings an order's stops ask for are stored with it and survive a
// restart; they are part of the order's content (a repeat of the client id with other
// headings is another order), and an order without any keeps the hash it always had.
TEST_F(SqliteStoreTest, StopHeadingsSurviveAReopenAndArePartOfTheContent) {
  engine::Order posed = MakeOrder("o1", "c1", {4, 5}, 12);
  posed.stop_headings = {{0, -1.5707963267948966}, {2, 3.141592653589793}};
  engine::Order plain = posed;
  plain.stop_headings.clear();
  EXPECT_NE(OrderContentHash(posed), OrderContentHash(plain));
  {
    auto store = OpenOrDie(db_path());
    ASSERT_NE(store, nullptr);
    ASSERT_TRUE(store->InsertOrder(posed, "").ok());
    ASSERT_TRUE(store->InsertOrder(MakeOrder("o2", "c2"), "").ok());
  }
  auto store = OpenOrDie(db_path());
  ASSERT_NE(store, nullptr);
  auto o1 = store->GetOrder("o1");
  ASSERT_TRUE(o1.ok()) << o1.error().message;
  EXPECT_EQ(o1->order.stop_headings, posed.stop_headings);  // bit-exact
  EXPECT_EQ(o1->content_hash, OrderContentHash(posed));
  auto o2 = store->GetOrder("o2");
  ASSERT_TRUE(o2.ok()) << o2.error().message;
  EXPECT_TRUE(o2->order.stop_headings.empty());
}

TEST_F(SqliteStoreTest, StateTransitionsFollowTheLifecycleAndAreJournaledInOrder) {
  auto store = OpenOrDie(db_path());
  ASSERT_NE(store, nullptr);
  ASSERT_TRUE(store->InsertOrder(MakeOrder("a", "ca"), "").ok());
  ASSERT_TRUE(store->InsertOrder(MakeOrder("b", "cb"), "").ok());
  const std::vector<std::string> team = {"R1"};
  ASSERT_TRUE(store->TransitionOrder({"a", OrderState::kAssigned, 2.0, team, "won", {}, ""}).ok());
  ASSERT_TRUE(store->TransitionOrder({"b", OrderState::kCancelled, 2.5, {}, "client", {}, ""}).ok());
  ASSERT_TRUE(store->TransitionOrder({"a", OrderState::kInProgress, 3.0, {}, "picking", {}, ""}).ok());
  ASSERT_TRUE(store->AppendProgress("a", 3.5, "picked at P1").ok());
  ASSERT_TRUE(store->TransitionOrder({"a", OrderState::kCompleted, 4.0, {}, "dropped", {}, ""}).ok());

  // Forbidden moves change nothing and journal nothing.
  const size_t journal = store->ListEvents({}).value().size();
  auto back = store->TransitionOrder({"a", OrderState::kAssigned, 5.0, {}, "", {}, ""});
  ASSERT_FALSE(back.ok());
  EXPECT_EQ(back.error().code, ErrorCode::kFailedPrecondition);
  EXPECT_NE(back.error().message.find("from completed to assigned"), std::string::npos)
      << back.error().message;
  EXPECT_EQ(store->TransitionOrder({"b", OrderState::kCancelled, 5.0, {}, "", {}, ""}).error().code,
            ErrorCode::kFailedPrecondition);
  EXPECT_EQ(store->TransitionOrder({"zz", OrderState::kAssigned, 5.0, {}, "", {}, ""}).error().code,
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
  const auto a_events = store->ListEvents({"a", 0, 100}).value();  // (a range-for over value() of a temporary dangles)
  for (const OrderEvent& e : a_events) {
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
    ASSERT_TRUE(store->InsertOrder(MakeOrder("a", "ca"), "").ok());
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
    ASSERT_TRUE(store->InsertOrder(MakeOrder(id, "c" + std::to_string(i)), "").ok());
    if (i % 3 == 0) {
      ASSERT_TRUE(store->TransitionOrder({id, OrderState::kAssigned, 1, {}, "", {}, ""}).ok());
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
      ASSERT_TRUE(store->InsertOrder(MakeOrder("late", "c-late"), "").ok());
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

}  // namespace
}  // namespace dispatch::storage::testing
