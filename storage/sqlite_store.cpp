// SqliteStore: opening and migrations, orders and their journal, transactions (robots,
// assignments and map versions are in sqlite_store_fleet.cpp; the statement wrapper in
// sqlite_statement.h).
#include "storage/sqlite_store.h"

#include <sqlite3.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "storage/migrations.h"
#include "storage/record_json.h"
#include "storage/sqlite_statement.h"

namespace dispatch::storage {
namespace {

using engine::OrderState;

constexpr const char* kOrderColumns =
    "id, client_id, state, priority, formation, created_time, updated_time, content_hash, "
    "robots, reason, body, seq, distance";
constexpr const char* kEventColumns =
    "id, order_id, type, state, previous_state, time, robots, detail, actor";

}  // namespace

// --- Opening --------------------------------------------------------------------------

Result<std::unique_ptr<SqliteStore>> SqliteStore::Open(const std::string& path,
                                                       SqliteOptions options) {
  const std::string context = "cannot open store '" + path + "'";
  sqlite3* db = nullptr;
  const int rc = sqlite3_open_v2(path.c_str(), &db,
                                 SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX,
                                 nullptr);
  if (rc != SQLITE_OK) {
    const std::string message = db != nullptr ? sqlite3_errmsg(db) : sqlite3_errstr(rc);
    sqlite3_close(db);
    return engine::IoError(context + ": " + message);
  }
  std::unique_ptr<SqliteStore> store(new SqliteStore(path, std::move(options), db));
  std::lock_guard lock(store->mu_);
  if (Status s = store->Configure(); !s.ok()) return WithContext(context, s.error());
  if (Status s = store->Migrate(); !s.ok()) return WithContext(context, s.error());
  store->hooks_enabled_ = true;
  return Result<std::unique_ptr<SqliteStore>>(std::move(store));
}

SqliteStore::SqliteStore(std::string path, SqliteOptions options, sqlite3* db)
    : path_(std::move(path)), options_(std::move(options)), db_(db) {}

SqliteStore::~SqliteStore() {
  for (auto& [sql, stmt] : statements_) sqlite3_finalize(stmt);
  sqlite3_close(db_);
}

Status SqliteStore::Configure() {
  sqlite3_extended_result_codes(db_, 1);
  sqlite3_busy_timeout(db_, options_.busy_timeout_ms);
  // The first statement reads the file header: a non-SQLite file fails here.
  Result<Statement> wal = Prepare("PRAGMA journal_mode = WAL");
  if (!wal.ok()) return wal.error();
  Result<bool> row = wal.value().Step();
  if (!row.ok()) return row.error();
  const std::string mode = *row ? wal.value().ColText(0) : std::string();
  if (mode != "wal") return engine::IoError("cannot switch to WAL (journal mode is '" + mode + "')");
  if (Status s = Exec(options_.full_sync ? "PRAGMA synchronous = FULL" : "PRAGMA synchronous = NORMAL");
      !s.ok()) {
    return s;
  }
  return Exec("PRAGMA foreign_keys = ON");
}

Status SqliteStore::Migrate() {
  if (Status s = Exec("CREATE TABLE IF NOT EXISTS schema_migrations ("
                      "version INTEGER PRIMARY KEY, name TEXT NOT NULL, "
                      "applied_at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%SZ', 'now')))");
      !s.ok()) {
    return s;
  }
  const std::span<const Migration> migrations = Migrations();
  const std::int64_t known = static_cast<std::int64_t>(migrations.size());
  // The applied versions must be exactly 1..max, with max <= known.
  auto applied = [&]() -> Result<std::int64_t> {
    Result<Statement> q = Prepare("SELECT max(version), count(*) FROM schema_migrations");
    if (!q.ok()) return q.error();
    Result<bool> row = q.value().Step();
    if (!row.ok()) return row.error();
    const std::int64_t max_version = q.value().ColInt(0);
    const std::int64_t count = q.value().ColInt(1);
    if (max_version > known) {
      return engine::IoError("database schema version " + std::to_string(max_version) +
                             " is newer than this program supports (" + std::to_string(known) +
                             ")");
    }
    if (count != max_version) {
      return engine::IoError("schema_migrations is inconsistent: " + std::to_string(count) +
                             " rows up to version " + std::to_string(max_version));
    }
    return max_version;
  };
  Result<std::int64_t> current = applied();
  if (!current.ok()) return current.error();
  // Each pending migration re-checks and applies under the write lock, so two processes
  // opening a new file at once apply every migration exactly once.
  for (const Migration& m : migrations) {
    if (m.version <= *current) continue;
    Status s = InTransaction([&]() -> Status {
      Result<std::int64_t> now = applied();
      if (!now.ok()) return now.error();
      if (m.version <= *now) return engine::Ok{};  // another connection applied it
      char* message = nullptr;
      if (sqlite3_exec(db_, m.sql, nullptr, nullptr, &message) != SQLITE_OK) {
        const std::string text = message != nullptr ? message : sqlite3_errmsg(db_);
        sqlite3_free(message);
        return engine::IoError("migration " + std::to_string(m.version) + " (" + m.name +
                               ") failed: " + text);
      }
      Result<Statement> insert =
          Prepare("INSERT INTO schema_migrations (version, name) VALUES (?, ?)");
      if (!insert.ok()) return insert.error();
      return insert.value().Int(1, m.version).Text(2, m.name).Run();
    });
    if (!s.ok()) return s;
  }
  schema_version_ = static_cast<int>(known);
  return engine::Ok{};
}

// --- Helpers --------------------------------------------------------------------------

Error SqliteStore::SqliteError(std::string_view what) const {
  return engine::IoError("sqlite '" + path_ + "': " + std::string(what) + ": " +
                         sqlite3_errmsg(db_) + " [" +
                         sqlite3_errstr(sqlite3_extended_errcode(db_)) + "]");
}

Result<SqliteStore::Statement> SqliteStore::Prepare(const std::string& sql) {
  auto it = statements_.find(sql);
  if (it == statements_.end()) {
    sqlite3_stmt* stmt = nullptr;
    if (sqlite3_prepare_v3(db_, sql.c_str(), static_cast<int>(sql.size()),
                           SQLITE_PREPARE_PERSISTENT, &stmt, nullptr) != SQLITE_OK) {
      return SqliteError("prepare \"" + sql + "\"");
    }
    it = statements_.emplace(sql, stmt).first;
  }
  return Statement(this, it->second);
}

Status SqliteStore::Exec(const char* sql) {
  if (sqlite3_exec(db_, sql, nullptr, nullptr, nullptr) != SQLITE_OK) return SqliteError(sql);
  return engine::Ok{};
}

Status SqliteStore::InTransaction(const std::function<Status()>& write) {
  const bool outer = tx_depth_ == 0;
  const std::string savepoint = "sp" + std::to_string(tx_depth_);
  if (Status s = Exec(outer ? "BEGIN IMMEDIATE" : ("SAVEPOINT " + savepoint).c_str()); !s.ok()) {
    return s;
  }
  auto rollback = [&] {
    if (outer) {
      if (sqlite3_get_autocommit(db_) == 0) (void)Exec("ROLLBACK");
    } else {
      (void)Exec(("ROLLBACK TO " + savepoint).c_str());
      (void)Exec(("RELEASE " + savepoint).c_str());
    }
  };
  ++tx_depth_;
  Status result = engine::Ok{};
  try {
    result = write();
  } catch (...) {
    --tx_depth_;
    rollback();
    throw;
  }
  --tx_depth_;
  if (result.ok()) {
    Status commit = Exec(outer ? "COMMIT" : ("RELEASE " + savepoint).c_str());
    if (commit.ok()) return result;
    result = commit;
  }
  rollback();
  return result;
}

Result<OrderRecord> SqliteStore::ReadOrder(Statement& stmt) {
  OrderRecord r;
  r.order.id = stmt.ColText(0);
  r.order.client_id = stmt.ColText(1);
  const auto state = engine::ParseOrderState(stmt.ColText(2));
  if (!state) return Corrupt("state of order '" + r.order.id + "'");
  r.order.state = *state;
  r.order.priority = static_cast<int>(stmt.ColInt(3));
  r.order.formation = stmt.ColInt(4) != 0;
  r.order.created_time = stmt.ColReal(5);
  r.updated_time = stmt.ColReal(6);
  r.content_hash = stmt.ColText(7);
  Result<std::vector<std::string>> robots = DecodeStrings(stmt.ColText(8));
  if (!robots.ok()) return WithContext("order '" + r.order.id + "'", robots.error());
  r.robots = std::move(robots).value();
  r.reason = stmt.ColText(9);
  r.distance = stmt.ColReal(12);
  if (Status s = DecodeOrderBody(stmt.ColText(10), r.order); !s.ok()) {
    return WithContext("order '" + r.order.id + "'", s.error());
  }
  return r;
}

Result<OrderEvent> SqliteStore::ReadEvent(Statement& stmt) {
  OrderEvent e;
  e.id = stmt.ColInt(0);
  e.order_id = stmt.ColText(1);
  const auto type = ParseOrderEventType(stmt.ColText(2));
  const auto state = engine::ParseOrderState(stmt.ColText(3));
  if (!type || !state) return Corrupt("order event " + std::to_string(e.id));
  e.type = *type;
  e.state = *state;
  if (!stmt.ColNull(4)) {
    e.previous_state = engine::ParseOrderState(stmt.ColText(4));
    if (!e.previous_state) return Corrupt("order event " + std::to_string(e.id));
  }
  e.time = stmt.ColReal(5);
  Result<std::vector<std::string>> robots = DecodeStrings(stmt.ColText(6));
  if (!robots.ok()) return WithContext("order event " + std::to_string(e.id), robots.error());
  e.robots = std::move(robots).value();
  e.detail = stmt.ColText(7);
  e.actor = stmt.ColText(8);
  return e;
}

Result<OrderEvent> SqliteStore::InsertEvent(const OrderEvent& event) {
  Result<std::string> robots = EncodeStrings(event.robots);
  if (!robots.ok()) return robots.error();
  Result<Statement> stmt = Prepare(
      "INSERT INTO order_events (order_id, type, state, previous_state, time, robots, detail, actor) "
      "VALUES (?, ?, ?, ?, ?, ?, ?, ?)");
  if (!stmt.ok()) return stmt.error();
  Statement& s = stmt.value();
  s.Text(1, event.order_id).Text(2, OrderEventTypeName(event.type));
  s.Text(3, engine::OrderStateName(event.state));
  if (event.previous_state) {
    s.Text(4, engine::OrderStateName(*event.previous_state));
  } else {
    s.Null(4);
  }
  s.Real(5, event.time).Text(6, robots.value()).Text(7, event.detail).Text(8, event.actor);
  if (Status run = s.Run(); !run.ok()) return run.error();
  OrderEvent stored = event;
  stored.id = sqlite3_last_insert_rowid(db_);
  return stored;
}

Result<OrderRecord> SqliteStore::FindOrder(const char* column, const std::string& key) {
  Result<Statement> stmt = Prepare(std::string("SELECT ") + kOrderColumns +
                                   " FROM orders WHERE " + column + " = ?");
  if (!stmt.ok()) return stmt.error();
  stmt.value().Text(1, key);
  Result<bool> row = stmt.value().Step();
  if (!row.ok()) return row.error();
  if (!*row) {
    return engine::NotFound(std::string(column) == "id" ? "no order with id '" + key + "'"
                                                        : "no order with client id '" + key + "'");
  }
  return ReadOrder(stmt.value());
}

// --- Orders ---------------------------------------------------------------------------

Result<InsertOrderResult> SqliteStore::InsertOrder(const engine::Order& order, const std::string& actor) {
  if (order.id.empty() || order.client_id.empty()) {
    return engine::InvalidArgument("an order needs an id and a client id");
  }
  if (order.state != OrderState::kAccepted) {
    return engine::InvalidArgument("order '" + order.id + "' must be inserted as accepted, not " +
                                   engine::OrderStateName(order.state));
  }
  if (order.picks.empty()) return engine::InvalidArgument("order '" + order.id + "' has no picks");
  if (!std::isfinite(order.created_time)) {
    return engine::InvalidArgument("order '" + order.id + "': created_time must be finite");
  }
  Result<std::string> body = EncodeOrderBody(order);
  if (!body.ok()) return body.error();
  const std::string hash = OrderContentHash(order);

  std::lock_guard lock(mu_);
  std::optional<InsertOrderResult> out;
  Status status = InTransaction([&]() -> Status {
    Result<OrderRecord> existing = FindOrder("client_id", order.client_id);
    if (existing.ok()) {
      if (existing->content_hash != hash) {
        return FailedPrecondition("client order id '" + order.client_id +
                                  "' was already used for order '" + existing->order.id +
                                  "' with different content");
      }
      out = InsertOrderResult{existing.value(), false};
      return engine::Ok{};
    }
    if (existing.error().code != engine::ErrorCode::kNotFound) return existing.error();
    Result<OrderRecord> same_id = FindOrder("id", order.id);
    if (same_id.ok()) {
      return FailedPrecondition("order id '" + order.id + "' already belongs to client order id '" +
                                same_id->order.client_id + "'");
    }
    if (same_id.error().code != engine::ErrorCode::kNotFound) return same_id.error();

    Result<Statement> insert = Prepare(
        "INSERT INTO orders (id, client_id, state, priority, formation, created_time, "
        "updated_time, content_hash, robots, reason, body) "
        "VALUES (?, ?, ?, ?, ?, ?, ?, ?, '[]', '', ?)");
    if (!insert.ok()) return insert.error();
    Status run = insert.value()
                     .Text(1, order.id)
                     .Text(2, order.client_id)
                     .Text(3, engine::OrderStateName(order.state))
                     .Int(4, order.priority)
                     .Int(5, order.formation ? 1 : 0)
                     .Real(6, order.created_time)
                     .Real(7, order.created_time)
                     .Text(8, hash)
                     .Text(9, body.value())
                     .Run();
    if (!run.ok()) return run;
    OrderEvent created;
    created.order_id = order.id;
    created.type = OrderEventType::kCreated;
    created.state = OrderState::kAccepted;
    created.time = order.created_time;
    created.detail = "accepted";
    created.actor = actor;
    Result<OrderEvent> event = InsertEvent(created);
    if (!event.ok()) return event.error();
    OrderRecord record;
    record.order = order;
    record.content_hash = hash;
    record.updated_time = order.created_time;
    out = InsertOrderResult{std::move(record), true};
    return engine::Ok{};
  });
  if (!status.ok()) return WithContext("insert order '" + order.id + "'", status.error());
  return std::move(*out);
}

Result<OrderRecord> SqliteStore::GetOrder(const std::string& order_id) {
  std::lock_guard lock(mu_);
  return FindOrder("id", order_id);
}

Result<OrderRecord> SqliteStore::GetOrderByClientId(const std::string& client_id) {
  std::lock_guard lock(mu_);
  return FindOrder("client_id", client_id);
}

Result<OrderPage> SqliteStore::ListOrders(const OrderQuery& query) {
  std::int64_t after = 0;
  if (!query.page_token.empty()) {
    const char* begin = query.page_token.data();
    const char* end = begin + query.page_token.size();
    auto [ptr, ec] = std::from_chars(begin, end, after);
    if (ec != std::errc() || ptr != end || after < 0) {
      return engine::InvalidArgument("invalid page token '" + query.page_token + "'");
    }
  }
  const int page_size =
      query.page_size <= 0 ? 100 : std::min(query.page_size, kMaxPageSize);
  std::string sql = std::string("SELECT ") + kOrderColumns + " FROM orders WHERE seq > ?";
  if (!query.states.empty()) {
    sql += " AND state IN (";
    for (std::size_t i = 0; i < query.states.size(); ++i) sql += i == 0 ? "?" : ", ?";
    sql += ")";
  }
  sql += " ORDER BY seq LIMIT ?";

  std::lock_guard lock(mu_);
  Result<Statement> stmt = Prepare(sql);
  if (!stmt.ok()) return stmt.error();
  Statement& s = stmt.value();
  int index = 1;
  s.Int(index++, after);
  for (OrderState state : query.states) s.Text(index++, engine::OrderStateName(state));
  s.Int(index, page_size + 1);  // one more tells whether a next page exists
  OrderPage page;
  std::int64_t last_seq = after;
  for (;;) {
    Result<bool> row = s.Step();
    if (!row.ok()) return row.error();
    if (!*row) break;
    if (static_cast<int>(page.orders.size()) == page_size) {
      page.next_page_token = std::to_string(last_seq);
      break;
    }
    Result<OrderRecord> record = ReadOrder(s);
    if (!record.ok()) return record.error();
    page.orders.push_back(std::move(record).value());
    last_seq = s.ColInt(11);
  }
  return page;
}

Result<OrderEvent> SqliteStore::TransitionOrder(const OrderTransition& t) {
  if (!std::isfinite(t.time)) return engine::InvalidArgument("transition time must be finite");
  if (t.distance && !(std::isfinite(*t.distance) && *t.distance >= 0)) {
    return engine::InvalidArgument("transition distance must be a finite number of metres >= 0");
  }
  std::lock_guard lock(mu_);
  std::optional<OrderEvent> out;
  Status status = InTransaction([&]() -> Status {
    Result<OrderRecord> current = FindOrder("id", t.order_id);
    if (!current.ok()) return current.error();
    const OrderState from = current->order.state;
    if (!engine::CanTransition(from, t.to)) {
      return FailedPrecondition(std::string("order '") + t.order_id + "' cannot go from " +
                                engine::OrderStateName(from) + " to " +
                                engine::OrderStateName(t.to));
    }
    const std::vector<std::string>& robots = t.robots ? *t.robots : current->robots;
    Result<std::string> robots_json = EncodeStrings(robots);
    if (!robots_json.ok()) return robots_json.error();
    const bool ends_badly = t.to == OrderState::kCancelled || t.to == OrderState::kFailed;
    Result<Statement> update = Prepare(
        "UPDATE orders SET state = ?, updated_time = ?, robots = ?, reason = ?, distance = ? WHERE id = ?");
    if (!update.ok()) return update.error();
    Status run = update.value()
                     .Text(1, engine::OrderStateName(t.to))
                     .Real(2, t.time)
                     .Text(3, robots_json.value())
                     .Text(4, ends_badly ? t.detail : current->reason)
                     .Real(5, t.distance.value_or(current->distance))
                     .Text(6, t.order_id)
                     .Run();
    if (!run.ok()) return run;
    OrderEvent event;
    event.order_id = t.order_id;
    event.type = OrderEventType::kStateChanged;
    event.state = t.to;
    event.previous_state = from;
    event.time = t.time;
    event.robots = robots;
    event.detail = t.detail;
    event.actor = t.actor;
    Result<OrderEvent> stored = InsertEvent(event);
    if (!stored.ok()) return stored.error();
    out = std::move(stored).value();
    return engine::Ok{};
  });
  if (!status.ok()) return WithContext("transition order '" + t.order_id + "'", status.error());
  return std::move(*out);
}

Result<OrderEvent> SqliteStore::AppendProgress(const std::string& order_id, double time,
                                               const std::string& detail) {
  if (!std::isfinite(time)) return engine::InvalidArgument("event time must be finite");
  std::lock_guard lock(mu_);
  std::optional<OrderEvent> out;
  Status status = InTransaction([&]() -> Status {
    Result<OrderRecord> current = FindOrder("id", order_id);
    if (!current.ok()) return current.error();
    OrderEvent event;
    event.order_id = order_id;
    event.type = OrderEventType::kProgress;
    event.state = current->order.state;
    event.time = time;
    event.robots = current->robots;
    event.detail = detail;
    Result<OrderEvent> stored = InsertEvent(event);
    if (!stored.ok()) return stored.error();
    out = std::move(stored).value();
    return engine::Ok{};
  });
  if (!status.ok()) return WithContext("journal order '" + order_id + "'", status.error());
  return std::move(*out);
}

Result<std::vector<OrderEvent>> SqliteStore::ListEvents(const EventQuery& query) {
  if (query.limit < 1) return engine::InvalidArgument("event limit must be >= 1");
  std::string sql = std::string("SELECT ") + kEventColumns + " FROM order_events WHERE id > ?";
  if (query.order_id) sql += " AND order_id = ?";
  sql += " ORDER BY id LIMIT ?";
  std::lock_guard lock(mu_);
  Result<Statement> stmt = Prepare(sql);
  if (!stmt.ok()) return stmt.error();
  Statement& s = stmt.value();
  int index = 1;
  s.Int(index++, query.after_id);
  if (query.order_id) s.Text(index++, *query.order_id);
  s.Int(index, query.limit);
  std::vector<OrderEvent> events;
  for (;;) {
    Result<bool> row = s.Step();
    if (!row.ok()) return row.error();
    if (!*row) break;
    Result<OrderEvent> event = ReadEvent(s);
    if (!event.ok()) return event.error();
    events.push_back(std::move(event).value());
  }
  return events;
}

// --- Transactions ---------------------------------------------------------------------

Status SqliteStore::RunInTransaction(const std::function<Status(Store&)>& body) {
  std::lock_guard lock(mu_);
  return InTransaction([&] { return body(*this); });
}

}  // namespace dispatch::storage
