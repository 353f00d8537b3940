// The core's journal in SQLite (storage/journal_store.h, storage/journal_json.h): inputs of
// every kind read back exactly as written, runs are kept by the retention, paging, the
// truncated mark, a run's setup round trip, and the errors.
#include "storage/journal_store.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sqlite3.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "engine/io/map_json.h"
#include "engine/map/chu2024_floor.h"
#include "storage/journal_json.h"
#include "temp_dir.h"

namespace dispatch::storage::testing {
namespace {

using engine::CoreInput;
using engine::JournalEntry;

std::vector<JournalEntry> SampleEntries() {
  std::vector<JournalEntry> out;
  auto add = [&](CoreInput in, std::string output) {
    out.push_back(JournalEntry{out.size() + 1, std::move(in), std::move(output)});
  };
  CoreInput order;
  order.kind = CoreInput::Kind::kAddOrder;
  engine::Order o;
  o.id = "ord-7";
  o.client_id = "wms \"A\"-7";
  o.priority = 2;
  o.picks = {3, 9};
  o.drop = 12;
  o.formation = true;
  o.work_time = 4.5;
  o.created_time = 0.1 + 0.2;  // not exactly 0.3
  o.release_time = 1.0 / 3.0;
  order.order = o;
  order.robots = {"R2", "R10"};
  add(order, "");
  CoreInput restore;
  restore.kind = CoreInput::Kind::kRestoreRobot;
  engine::Robot r;
  r.id = "R2";
  r.state = engine::RobotState::kWorking;
  r.pose.position = {1.25, std::sqrt(2.0)};
  r.pose.heading = -std::acos(-1.0) / 7;
  r.current_point = 3;
  r.task_queue = {"ord-7"};
  r.battery = 0.875;
  restore.robot = r;
  engine::Assignment a;
  a.robot_id = "R2";
  a.plan_id = 4;
  a.order_ids = {"ord-7"};
  a.plan.robot_id = "R2";
  a.plan.waypoints = {{5, 3, {1.25, 1.5}, 0.7, engine::WaypointAction::kPick, 5.0, {}, {}},
                      {6, 12, {2.0, 1.5}, 6.4, engine::WaypointAction::kDrop, 5.0, {}, {}}};
  a.released_up_to = 5;
  a.updated_time = 0.7;
  restore.plan = a;
  restore.place = true;
  add(restore, "");
  CoreInput report;
  report.kind = CoreInput::Kind::kReport;
  report.time = 12.000000000000002;
  report.robot_id = "R2";
  report.pose = r.pose;
  report.arc_id = 17;
  report.state = engine::RobotState::kMoving;
  report.battery = 0.5;
  report.sequence = 6;
  add(report, "ord-7 -> in_progress [R2]");
  CoreInput task;
  task.kind = CoreInput::Kind::kPlanTask;
  task.time = 13.5;
  task.robot_id = "R2";
  task.task = {"ord-7", true};
  add(task, "ord-7 -> completed [R2]; R2 plan p5 1 wp #0");
  CoreInput cancel;
  cancel.kind = CoreInput::Kind::kPlanCancel;
  cancel.time = 14;
  cancel.order_id = "ord-8";
  cancel.reason = "operator: \u00fcberf\u00e4llig";
  add(cancel, "error: no order ord-8");
  CoreInput awards;
  awards.kind = CoreInput::Kind::kPlanAwards;
  awards.time = 15;
  awards.ref = 2;
  awards.max = 4;
  add(awards, "");
  CoreInput committed;
  committed.kind = CoreInput::Kind::kCommitted;
  committed.ref = 2;
  committed.change = 6;
  add(committed, "");
  CoreInput result;
  result.kind = CoreInput::Kind::kRoundResult;
  result.ref = 2;
  result.cancelled = true;
  add(result, "");
  CoreInput reached;
  reached.kind = CoreInput::Kind::kReached;
  reached.time = 16;
  reached.robot_id = "R2";
  reached.sequence = 5;
  add(reached, "");  // without a pose
  CoreInput command;
  command.kind = CoreInput::Kind::kPlanCommand;
  command.time = 17;
  command.robot_id = "R2";
  command.command = engine::OperatorCommand{engine::RobotCommandKind::kSend, "R2", "op-1", 4};
  add(command, "R2 plan p3 4 wp #0badcafe []");
  CoreInput restored;
  restored.kind = CoreInput::Kind::kRestoreRobot;
  restored.robot = engine::Robot{};
  restored.robot->id = "R3";
  restored.marks = {"op-1", "op-2", true};
  add(restored, "");
  return out;
}

void ExpectSameInput(const CoreInput& a, const CoreInput& b) {
  EXPECT_EQ(a.kind, b.kind);
  EXPECT_EQ(a.time, b.time);  // bit for bit
  EXPECT_EQ(a.robot_id, b.robot_id);
  EXPECT_EQ(a.order_id, b.order_id);
  EXPECT_EQ(a.reason, b.reason);
  ASSERT_EQ(a.order.has_value(), b.order.has_value());
  if (a.order) {
    EXPECT_EQ(a.order->id, b.order->id);
    EXPECT_EQ(a.order->client_id, b.order->client_id);
    EXPECT_EQ(a.order->priority, b.order->priority);
    EXPECT_EQ(a.order->picks, b.order->picks);
    EXPECT_EQ(a.order->drop, b.order->drop);
    EXPECT_EQ(a.order->formation, b.order->formation);
    EXPECT_EQ(a.order->work_time, b.order->work_time);
    EXPECT_EQ(a.order->created_time, b.order->created_time);
    EXPECT_EQ(a.order->release_time, b.order->release_time);
    EXPECT_EQ(a.order->state, b.order->state);
  }
  EXPECT_EQ(a.robots, b.robots);
  ASSERT_EQ(a.robot.has_value(), b.robot.has_value());
  if (a.robot) {
    EXPECT_EQ(a.robot->id, b.robot->id);
    EXPECT_EQ(a.robot->state, b.robot->state);
    EXPECT_EQ(a.robot->pose.position, b.robot->pose.position);
    EXPECT_EQ(a.robot->pose.heading, b.robot->pose.heading);
    EXPECT_EQ(a.robot->current_point, b.robot->current_point);
    EXPECT_EQ(a.robot->task_queue, b.robot->task_queue);
    EXPECT_EQ(a.robot->battery, b.robot->battery);
  }
  ASSERT_EQ(a.plan.has_value(), b.plan.has_value());
  if (a.plan) {
    EXPECT_EQ(a.plan->plan_id, b.plan->plan_id);
    EXPECT_EQ(a.plan->order_ids, b.plan->order_ids);
    EXPECT_EQ(a.plan->released_up_to, b.plan->released_up_to);
    ASSERT_EQ(a.plan->plan.waypoints.size(), b.plan->plan.waypoints.size());
    for (std::size_t i = 0; i < a.plan->plan.waypoints.size(); ++i) {
      EXPECT_EQ(a.plan->plan.waypoints[i].eta, b.plan->plan.waypoints[i].eta);
      EXPECT_EQ(a.plan->plan.waypoints[i].point, b.plan->plan.waypoints[i].point);
      EXPECT_EQ(a.plan->plan.waypoints[i].action, b.plan->plan.waypoints[i].action);
    }
  }
  EXPECT_EQ(a.place, b.place);
  ASSERT_EQ(a.pose.has_value(), b.pose.has_value());
  if (a.pose) {
    EXPECT_EQ(a.pose->position, b.pose->position);
    EXPECT_EQ(a.pose->heading, b.pose->heading);
  }
  EXPECT_EQ(a.arc_id, b.arc_id);
  EXPECT_EQ(a.state, b.state);
  EXPECT_EQ(a.battery, b.battery);
  EXPECT_EQ(a.sequence, b.sequence);
  EXPECT_EQ(a.task.order_id, b.task.order_id);
  EXPECT_EQ(a.task.dropped, b.task.dropped);
  EXPECT_EQ(a.ref, b.ref);
  EXPECT_EQ(a.change, b.change);
  EXPECT_EQ(a.max, b.max);
  EXPECT_EQ(a.cancelled, b.cancelled);
  EXPECT_EQ(a.marks, b.marks);
  ASSERT_EQ(a.command.has_value(), b.command.has_value());
  if (a.command) {
    EXPECT_EQ(a.command->kind, b.command->kind);
    EXPECT_EQ(a.command->robot, b.command->robot);
    EXPECT_EQ(a.command->by, b.command->by);
    EXPECT_EQ(a.command->to, b.command->to);
  }
}

TEST(JournalStoreTest, EntriesOfEveryKindReadBackExactly) {
  TempDir dir;
  const std::string path = (dir.path() / "j.db").string();
  auto store = JournalStore::Open(path);
  ASSERT_TRUE(store.ok()) << store.error().message;
  auto run = (*store)->StartRun(1.5, "{}", 3);
  ASSERT_TRUE(run.ok()) << run.error().message;
  const std::vector<JournalEntry> entries = SampleEntries();
  auto written = (*store)->Append(*run, entries);
  ASSERT_TRUE(written.ok()) << written.error().message;
  EXPECT_GT(*written, 0u);
  // Read back in pages of 4.
  std::vector<JournalEntry> read;
  for (std::uint64_t after = 0;;) {
    auto page = (*store)->Read(*run, after, 4);
    ASSERT_TRUE(page.ok()) << page.error().message;
    if (page->empty()) break;
    after = page->back().seq;
    read.insert(read.end(), page->begin(), page->end());
  }
  ASSERT_EQ(read.size(), entries.size());
  for (std::size_t i = 0; i < entries.size(); ++i) {
    SCOPED_TRACE(engine::CoreInputKindName(entries[i].input.kind));
    EXPECT_EQ(read[i].seq, entries[i].seq);
    EXPECT_EQ(read[i].output, entries[i].output);
    ExpectSameInput(read[i].input, entries[i].input);
  }
  auto runs = (*store)->Runs();
  ASSERT_TRUE(runs.ok());
  ASSERT_EQ(runs->size(), 1u);
  EXPECT_EQ((*runs)[0].entries, entries.size());
  EXPECT_EQ((*runs)[0].bytes, *written);
  EXPECT_FALSE((*runs)[0].truncated);
  ASSERT_TRUE((*store)->Append(*run, {}, /*truncated=*/true).ok());
  EXPECT_TRUE((*(*store)->Runs())[0].truncated);
  EXPECT_EQ((*store)->Append(*run + 1, entries).error().code, engine::ErrorCode::kNotFound);
}

TEST(JournalStoreTest, StartRunKeepsTheNewestRuns) {
  TempDir dir;
  const std::string path = (dir.path() / "j.db").string();
  auto store = JournalStore::Open(path);
  ASSERT_TRUE(store.ok());
  std::vector<std::int64_t> runs;
  for (int i = 0; i < 4; ++i) {
    auto run = (*store)->StartRun(i, "{}", 2);
    ASSERT_TRUE(run.ok());
    ASSERT_TRUE((*store)->Append(*run, SampleEntries()).ok());
    runs.push_back(*run);
  }
  auto kept = (*store)->Runs();
  ASSERT_TRUE(kept.ok());
  ASSERT_EQ(kept->size(), 2u);
  EXPECT_EQ((*kept)[0].run, runs[2]);
  EXPECT_EQ((*kept)[1].run, runs[3]);
  auto gone = (*store)->Read(runs[0], 0, 100);
  ASSERT_TRUE(gone.ok());
  EXPECT_TRUE(gone->empty()) << "a deleted run's entries go with it";
  EXPECT_FALSE((*store)->StartRun(9, "{}", 0).ok());
}

// SQL on the file itself; the rows of the first column of a query.
std::vector<std::string> Sql(const std::string& path, const std::string& sql) {
  sqlite3* db = nullptr;
  std::vector<std::string> rows;
  EXPECT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  auto row = [](void* out, int, char** values, char**) {
    static_cast<std::vector<std::string>*>(out)->push_back(values[0] ? values[0] : "");
    return 0;
  };
  char* message = nullptr;
  EXPECT_EQ(sqlite3_exec(db, sql.c_str(), row, &rows, &message), SQLITE_OK) << (message ? message : "");
  sqlite3_free(message);
  sqlite3_close(db);
  return rows;
}

// A journal written before the setups moved out of core_runs (whose counters every Append
// updates) and core_journal became a rowid table: read-only it reads as it is; opened for
// writing it is moved to the current layout with every run, setup and entry, and goes on.
TEST(JournalStoreTest, AnOlderLayoutIsReadAsItIsAndMovedOverWhenWritten) {
  TempDir dir;
  const std::string path = (dir.path() / "old.db").string();
  std::string sql =
      "CREATE TABLE core_runs (run INTEGER PRIMARY KEY AUTOINCREMENT, started_time REAL NOT NULL, setup TEXT NOT NULL,"
      "  entries INTEGER NOT NULL DEFAULT 0, bytes INTEGER NOT NULL DEFAULT 0, truncated INTEGER NOT NULL DEFAULT 0);"
      "CREATE TABLE core_journal (run INTEGER NOT NULL, seq INTEGER NOT NULL, time REAL NOT NULL, kind TEXT NOT NULL,"
      "  input TEXT NOT NULL, output TEXT NOT NULL, PRIMARY KEY (run, seq)) WITHOUT ROWID;"
      "INSERT INTO core_runs VALUES (4, 10.5, '{\"setup\": 4}', 3, 120, 1);";
  const std::vector<JournalEntry> entries = SampleEntries();
  for (std::size_t i = 0; i < 3; ++i) {
    auto input = EncodeCoreInput(entries[i].input);
    ASSERT_TRUE(input.ok());
    std::string quoted;
    for (char c : *input) quoted += c == '\'' ? std::string("''") : std::string(1, c);
    char time[32];
    std::snprintf(time, sizeof time, "%.17g", entries[i].input.time);
    sql += "INSERT INTO core_journal VALUES (4, " + std::to_string(entries[i].seq) + ", " + time + ", '" + engine::CoreInputKindName(entries[i].input.kind) + "', '" +
           quoted + "', '" + entries[i].output + "');";
  }
  Sql(path, sql);
  auto expect_old_run = [&](JournalStore& store) {
    auto runs = store.Runs();
    ASSERT_TRUE(runs.ok()) << runs.error().message;
    ASSERT_EQ(runs->size(), 1u);
    EXPECT_EQ((*runs)[0].run, 4);
    EXPECT_EQ((*runs)[0].started_time, 10.5);
    EXPECT_EQ((*runs)[0].setup, "{\"setup\": 4}");
    EXPECT_EQ((*runs)[0].entries, 3u);
    EXPECT_EQ((*runs)[0].bytes, 120u);
    EXPECT_TRUE((*runs)[0].truncated);
    auto read = store.Read(4, 0, 10);
    ASSERT_TRUE(read.ok()) << read.error().message;
    ASSERT_EQ(read->size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) {
      EXPECT_EQ((*read)[i].seq, entries[i].seq);
      EXPECT_EQ((*read)[i].output, entries[i].output);
      ExpectSameInput((*read)[i].input, entries[i].input);
    }
  };
  {
    auto read_only = JournalStore::Open(path, true);
    ASSERT_TRUE(read_only.ok()) << read_only.error().message;
    expect_old_run(**read_only);
  }
  EXPECT_EQ(Sql(path, "SELECT name FROM pragma_table_info('core_runs') WHERE name = 'setup'").size(), 1u)
      << "read-only leaves the file as it is";
  {
    auto store = JournalStore::Open(path);
    ASSERT_TRUE(store.ok()) << store.error().message;
    expect_old_run(**store);
    EXPECT_TRUE(Sql(path, "SELECT name FROM pragma_table_info('core_runs') WHERE name = 'setup'").empty());
    const auto journal_sql = Sql(path, "SELECT sql FROM sqlite_master WHERE name = 'core_journal'");
    ASSERT_EQ(journal_sql.size(), 1u);
    EXPECT_EQ(journal_sql[0].find("WITHOUT ROWID"), std::string::npos) << journal_sql[0];
    EXPECT_TRUE(Sql(path, "SELECT name FROM sqlite_master WHERE name = 'core_journal_new'").empty());
    auto next = (*store)->StartRun(20.0, "{\"setup\": 5}", 2);
    ASSERT_TRUE(next.ok()) << next.error().message;
    EXPECT_EQ(*next, 5);
    ASSERT_TRUE((*store)->Append(*next, entries).ok());
    auto runs = (*store)->Runs();
    ASSERT_TRUE(runs.ok());
    ASSERT_EQ(runs->size(), 2u);
    EXPECT_EQ((*runs)[1].setup, "{\"setup\": 5}");
    EXPECT_EQ((*runs)[1].entries, entries.size());
  }
  // Reopened: already the current layout, nothing moves.
  auto again = JournalStore::Open(path);
  ASSERT_TRUE(again.ok()) << again.error().message;
  auto read = (*again)->Read(5, 0, 100);
  ASSERT_TRUE(read.ok());
  EXPECT_EQ(read->size(), entries.size());
  auto third = (*again)->StartRun(30.0, "{}", 1);
  ASSERT_TRUE(third.ok());
  EXPECT_EQ(Sql(path, "SELECT run FROM core_run_setups"), std::vector<std::string>{"6"})
      << "a deleted run's setup goes with it";
}

TEST(JournalStoreTest, ReadOnlyNeedsAJournalAndCorruptRowsAreErrors) {
  TempDir dir;
  const std::string path = (dir.path() / "j.db").string();
  EXPECT_FALSE(JournalStore::Open(path, /*read_only=*/true).ok()) << "no such file";
  {
    auto store = JournalStore::Open(path);
    ASSERT_TRUE(store.ok());
  }
  auto read_only = JournalStore::Open(path, true);
  ASSERT_TRUE(read_only.ok()) << read_only.error().message;
  EXPECT_TRUE((*read_only)->Runs()->empty());
  EXPECT_FALSE(engine::ParseCoreInputKind("teleport").has_value());
  auto bad = DecodeCoreInput(CoreInput::Kind::kReport, 1.0, "{\"p\": \"here\"}");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code, engine::ErrorCode::kIoError);
  EXPECT_FALSE(DecodeCoreInput(CoreInput::Kind::kStep, 1.0, "[1, 2]").ok());
  // What a robot may send (the core ignores it) is journaled as sent.
  CoreInput odd;
  odd.kind = CoreInput::Kind::kReport;
  odd.pose = engine::Pose{{std::nan(""), std::numeric_limits<double>::infinity()}, -1e300 * 1e300};
  odd.battery = std::nan("");
  auto text = EncodeCoreInput(odd);
  ASSERT_TRUE(text.ok()) << text.error().message;
  auto back = DecodeCoreInput(CoreInput::Kind::kReport, 0.0, *text);
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_TRUE(std::isnan(back->pose->position.x()));
  EXPECT_EQ(back->pose->position.y(), std::numeric_limits<double>::infinity());
  EXPECT_EQ(back->pose->heading, -std::numeric_limits<double>::infinity());
  EXPECT_TRUE(std::isnan(*back->battery));
  EXPECT_FALSE(DecodeCoreInput(CoreInput::Kind::kReport, 0.0, "{\"p\": [\"big\", 0, 0]}").ok());
}

TEST(JournalStoreTest, ARunSetupRoundTrips) {
  auto floor = engine::BuildChu2024Floor();
  ASSERT_TRUE(floor.ok());
  RunSetup s;
  s.map_json = engine::WriteMapJson(*floor);
  s.map_source = "builtin:chu2024";
  s.strategy = "greedy";
  s.allocation.zeta = 0.0;
  s.allocation.work_time_override = 7.5;
  s.allocation.planner = engine::PlannerKind::kTimeWindows;
  s.allocation.turn_time = 1.5;
  s.allocation.drop_time = 0.0;
  s.allocation.routing = engine::RoutingKind::kHeat;
  s.allocation.heat_period = 30.0;
  s.allocation.formation_max_queue = 2;
  s.core.one_formation_per_pick = true;
  s.core.traffic.t_w1 = 3.25;
  s.core.traffic.head_on = engine::HeadOnPolicy::kAlwaysWait;
  s.core.traffic.priority_by_release = true;
  s.core.traffic.head_on_priority = true;
  s.core.traffic.head_on_give_way = true;
  s.core.traffic.execution = engine::PlanExecution::kOrder;
  s.core.traffic_control = false;
  s.route_cache_bytes = 1 << 20;
  s.route_table = "hub_labels";
  s.time_scale = 10;
  auto text = EncodeRunSetup(s);
  ASSERT_TRUE(text.ok()) << text.error().message;
  auto back = DecodeRunSetup(*text);
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->strategy, "greedy");
  EXPECT_EQ(back->allocation.zeta, 0.0);
  EXPECT_EQ(back->allocation.work_time_override, 7.5);
  EXPECT_EQ(back->allocation.planner, engine::PlannerKind::kTimeWindows);
  EXPECT_EQ(back->allocation.turn_time, 1.5);
  EXPECT_EQ(back->allocation.drop_time, 0.0);
  EXPECT_EQ(back->allocation.routing, engine::RoutingKind::kHeat);
  EXPECT_EQ(back->allocation.heat_period, 30.0);
  EXPECT_EQ(back->allocation.formation_max_queue, 2u);
  EXPECT_TRUE(back->core.one_formation_per_pick);
  EXPECT_EQ(back->core.traffic.t_w1, 3.25);
  EXPECT_EQ(back->core.traffic.head_on, engine::HeadOnPolicy::kAlwaysWait);
  EXPECT_TRUE(back->core.traffic.priority_by_release);
  EXPECT_TRUE(back->core.traffic.head_on_priority);
  EXPECT_TRUE(back->core.traffic.head_on_give_way);
  EXPECT_EQ(back->core.traffic.execution, engine::PlanExecution::kOrder);
  EXPECT_FALSE(back->core.traffic_control);
  EXPECT_EQ(back->route_cache_bytes, std::size_t{1} << 20);
  EXPECT_EQ(back->route_table, "hub_labels");
  auto map = engine::ParseMapJson(back->map_json);
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(engine::WriteMapJson(*map), s.map_json) << "the map reads back as written";
  EXPECT_FALSE(DecodeRunSetup("{\"version\": \"9\"}").ok());
  // A journal written before the planners were selectable ran the rules.
  auto old = nlohmann::json::parse(*text);
  old["allocation"].erase("planner");
  old["allocation"].erase("routing");
  auto before = DecodeRunSetup(old.dump());
  ASSERT_TRUE(before.ok()) << before.error().message;
  EXPECT_EQ(before->allocation.planner, engine::PlannerKind::kRules);
  EXPECT_EQ(before->allocation.routing, engine::RoutingKind::kFloyd);
  // ... and worked each order's t_w at its drop.
  old["allocation"].erase("drop_time");
  EXPECT_FALSE(DecodeRunSetup(old.dump()).value().allocation.drop_time.has_value());
  // ... and had no limit on a formation member's queue.
  old["allocation"].erase("formation_max_queue");
  EXPECT_EQ(DecodeRunSetup(old.dump()).value().allocation.formation_max_queue, 0u);
  old["core"].erase("priority_by_release");
  EXPECT_FALSE(DecodeRunSetup(old.dump()).value().core.traffic.priority_by_release);
  old["core"].erase("head_on_priority");  // first come, as before it
  old["core"].erase("head_on_give_way");
  EXPECT_FALSE(DecodeRunSetup(old.dump()).value().core.traffic.head_on_priority);
  EXPECT_FALSE(DecodeRunSetup(old.dump()).value().core.traffic.head_on_give_way);
  old["core"].erase("execution");  // at the planned departures, as before it
  EXPECT_EQ(DecodeRunSetup(old.dump()).value().core.traffic.execution, engine::PlanExecution::kTimes);
  old["route_table"] = "astar";
  EXPECT_FALSE(DecodeRunSetup(old.dump()).ok());
  old.erase("route_table");  // journals before it: the dense table
  EXPECT_EQ(DecodeRunSetup(old.dump()).value().route_table, "floyd");
  old["core"]["execution"] = "whenever";
  EXPECT_FALSE(DecodeRunSetup(old.dump()).ok());
  old["core"].erase("execution");
  old["allocation"]["planner"] = "magic";
  EXPECT_FALSE(DecodeRunSetup(old.dump()).ok());
}

}  // namespace
}  // namespace dispatch::storage::testing
