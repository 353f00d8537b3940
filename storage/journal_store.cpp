#include "storage/journal_store.h"

#include <sqlite3.h>

#include <utility>

#include "storage/journal_json.h"

namespace dispatch::storage {

// A prepared statement, finalized when it goes out of scope.
class JournalStore::Stmt {
 public:
  Stmt(sqlite3* db, const char* sql) { rc_ = sqlite3_prepare_v2(db, sql, -1, &stmt_, nullptr); }
  ~Stmt() { sqlite3_finalize(stmt_); }
  Stmt(const Stmt&) = delete;
  Stmt& operator=(const Stmt&) = delete;
  bool ok() const { return rc_ == SQLITE_OK; }
  sqlite3_stmt* get() { return stmt_; }
  void Text(int i, const std::string& s) {
    sqlite3_bind_text(stmt_, i, s.data(), static_cast<int>(s.size()), SQLITE_TRANSIENT);
  }
  void Int(int i, std::int64_t v) { sqlite3_bind_int64(stmt_, i, v); }
  void Real(int i, double v) { sqlite3_bind_double(stmt_, i, v); }
  std::string Col(int i) {
    const auto* p = reinterpret_cast<const char*>(sqlite3_column_text(stmt_, i));
    return p ? std::string(p, static_cast<std::size_t>(sqlite3_column_bytes(stmt_, i))) : std::string();
  }

 private:
  sqlite3_stmt* stmt_ = nullptr;
  int rc_ = SQLITE_OK;
};

JournalStore::JournalStore(sqlite3* db) : db_(db) {}

Result<std::unique_ptr<JournalStore>> JournalStore::Open(const std::string& path, bool read_only) {
  sqlite3* db = nullptr;
  const int flags = (read_only ? SQLITE_OPEN_READONLY : SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE) |
                    SQLITE_OPEN_NOMUTEX;
  const int rc = sqlite3_open_v2(path.c_str(), &db, flags, nullptr);
  if (rc != SQLITE_OK) {
    const std::string message = db ? sqlite3_errmsg(db) : sqlite3_errstr(rc);
    sqlite3_close(db);
    return engine::IoError("cannot open journal '" + path + "': " + message);
  }
  std::unique_ptr<JournalStore> store(new JournalStore(db));
  sqlite3_busy_timeout(db, 5000);
  if (read_only) {
    if (Status s = store->Exec("SELECT 1 FROM core_runs LIMIT 1"); !s.ok()) {
      return engine::IoError("'" + path + "' has no dispatch journal (core_runs): " + s.error().message);
    }
    store->setups_apart_ = store->HasTable("core_run_setups");
    return store;
  }
  if (Status s = store->Exec("PRAGMA journal_mode = WAL;"
                              "PRAGMA synchronous = NORMAL;"
                              "PRAGMA cache_size = -256;");  // 256 KiB: the journal is written, hardly read back
      !s.ok()) {
    return engine::IoError("cannot open journal '" + path + "': " + s.error().message);
  }
  if (Status s = store->Upgrade(); !s.ok()) return engine::IoError("cannot open journal '" + path + "': " + s.error().message);
  return store;
}

JournalStore::~JournalStore() {
  append_.reset();  // its statements are finalized before the connection closes
  sqlite3_close(db_);
}

bool JournalStore::HasTable(const char* name) {
  Stmt q(db_, "SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = ?");
  q.Text(1, name);
  return q.ok() && sqlite3_step(q.get()) == SQLITE_ROW;
}

// The layout (see the header): a run's setup (megabytes: the map) apart from its counters,
// which every Append updates (SQLite rewrites a whole row on update: with the setup in it, each
// Append read and wrote the map again), and the entries in a rowid table (a WITHOUT ROWID table
// keeps whole rows in its b-tree's keys, and an entry can be kilobytes). A journal written
// before that (setup in core_runs, core_journal WITHOUT ROWID) is moved over once.
Status JournalStore::Upgrade() {
  const std::string journal_table =
      " (run INTEGER NOT NULL, seq INTEGER NOT NULL, time REAL NOT NULL, kind TEXT NOT NULL,"
      "  input TEXT NOT NULL, output TEXT NOT NULL, PRIMARY KEY (run, seq));";
  const std::string setups_table = "CREATE TABLE core_run_setups (run INTEGER PRIMARY KEY, setup TEXT NOT NULL);";
  // Looked at and changed in one transaction: another process opening the file meanwhile
  // waits, then finds the tables made.
  if (Status s = Exec("BEGIN IMMEDIATE"); !s.ok()) return s;
  std::string sql;
  if (!HasTable("core_runs")) {
    sql = "CREATE TABLE core_runs ("
          "  run INTEGER PRIMARY KEY AUTOINCREMENT, started_time REAL NOT NULL,"
          "  entries INTEGER NOT NULL DEFAULT 0, bytes INTEGER NOT NULL DEFAULT 0,"
          "  truncated INTEGER NOT NULL DEFAULT 0);" +
          setups_table + "CREATE TABLE core_journal" + journal_table;
  } else if (!HasTable("core_run_setups")) {
    sql = setups_table +
          "INSERT INTO core_run_setups (run, setup) SELECT run, setup FROM core_runs;"
          "ALTER TABLE core_runs DROP COLUMN setup;"
          "CREATE TABLE core_journal_new" + journal_table +
          "INSERT INTO core_journal_new SELECT run, seq, time, kind, input, output FROM core_journal;"
          "DROP TABLE core_journal;"
          "ALTER TABLE core_journal_new RENAME TO core_journal;";
  }
  if (Status s = Exec(sql.c_str()); !s.ok()) {
    Rollback();
    return engine::IoError("making the journal's tables: " + s.error().message);
  }
  if (Status s = Exec("COMMIT"); !s.ok()) {
    Rollback();
    return s;
  }
  setups_apart_ = true;
  return engine::Ok{};
}

Status JournalStore::Exec(const char* sql) {
  char* message = nullptr;
  if (sqlite3_exec(db_, sql, nullptr, nullptr, &message) != SQLITE_OK) {
    std::string text = message ? message : sqlite3_errmsg(db_);
    sqlite3_free(message);
    return engine::IoError(text);
  }
  return engine::Ok{};
}

engine::Error JournalStore::Failed(const std::string& what) const {
  return engine::IoError("journal: " + what + ": " + sqlite3_errmsg(db_));
}

Result<std::int64_t> JournalStore::StartRun(double started_time, const std::string& setup, int keep_runs) {
  if (keep_runs < 1) return engine::InvalidArgument("journal: keep_runs must be >= 1");
  if (Status s = Exec("BEGIN IMMEDIATE"); !s.ok()) return s.error();
  auto fail = [this](const std::string& what) {
    engine::Error e = Failed(what);
    Rollback();
    return e;
  };
  Stmt insert(db_, "INSERT INTO core_runs (started_time) VALUES (?)");
  if (!insert.ok()) return fail("prepare run");
  insert.Real(1, started_time);
  if (sqlite3_step(insert.get()) != SQLITE_DONE) return fail("insert run");
  const std::int64_t run = sqlite3_last_insert_rowid(db_);
  Stmt insert_setup(db_, "INSERT INTO core_run_setups (run, setup) VALUES (?, ?)");
  if (!insert_setup.ok()) return fail("prepare run setup");
  insert_setup.Int(1, run);
  insert_setup.Text(2, setup);
  if (sqlite3_step(insert_setup.get()) != SQLITE_DONE) return fail("insert run setup");
  // The newest keep_runs runs stay (this one included).
  Stmt cutoff(db_, "SELECT run FROM core_runs ORDER BY run DESC LIMIT 1 OFFSET ?");
  if (!cutoff.ok()) return fail("prepare retention");
  cutoff.Int(1, keep_runs - 1);
  if (sqlite3_step(cutoff.get()) == SQLITE_ROW) {
    const std::int64_t oldest_kept = sqlite3_column_int64(cutoff.get(), 0);
    for (const char* sql : {"DELETE FROM core_journal WHERE run < ?", "DELETE FROM core_run_setups WHERE run < ?",
                            "DELETE FROM core_runs WHERE run < ?"}) {
      Stmt del(db_, sql);
      if (!del.ok()) return fail("prepare delete");
      del.Int(1, oldest_kept);
      if (sqlite3_step(del.get()) != SQLITE_DONE) return fail("delete old runs");
    }
  }
  if (Status s = Exec("COMMIT"); !s.ok()) return fail("commit");
  return run;
}

// Append's statements, prepared once: a batch is a few entries, and parsing its SQL again each
// time cost as much as writing them.
struct JournalStore::AppendStatements {
  explicit AppendStatements(sqlite3* db)
      : begin(db, "BEGIN IMMEDIATE"),
        insert(db, "INSERT INTO core_journal (run, seq, time, kind, input, output) VALUES (?, ?, ?, ?, ?, ?)"),
        update(db, "UPDATE core_runs SET entries = entries + ?, bytes = bytes + ?, truncated = MAX(truncated, ?) "
                   "WHERE run = ?"),
        commit(db, "COMMIT") {}
  bool ok() const { return begin.ok() && insert.ok() && update.ok() && commit.ok(); }
  Stmt begin, insert, update, commit;
};

Result<std::uint64_t> JournalStore::Append(std::int64_t run, const std::vector<engine::JournalEntry>& entries, bool truncated) {
  if (entries.empty() && !truncated) return std::uint64_t{0};
  if (!append_) {
    auto prepared = std::make_unique<AppendStatements>(db_);
    if (!prepared->ok()) return Failed("prepare append");
    append_ = std::move(prepared);
  }
  AppendStatements& st = *append_;
  // Each statement is reset after its step, so none holds the database when this returns.
  auto step = [](Stmt& stmt) {
    const int rc = sqlite3_step(stmt.get());
    sqlite3_reset(stmt.get());
    return rc;
  };
  if (step(st.begin) != SQLITE_DONE) return Failed("begin");
  auto fail = [this](const std::string& what) {
    engine::Error e = Failed(what);
    Rollback();
    return e;
  };
  std::uint64_t bytes = 0;
  for (const engine::JournalEntry& e : entries) {
    auto input = EncodeCoreInput(e.input);
    if (!input.ok()) {
      Rollback();
      return input.error();
    }
    st.insert.Int(1, run);
    st.insert.Int(2, static_cast<std::int64_t>(e.seq));
    st.insert.Real(3, e.input.time);
    st.insert.Text(4, engine::CoreInputKindName(e.input.kind));
    st.insert.Text(5, *input);
    st.insert.Text(6, e.output);
    if (step(st.insert) != SQLITE_DONE) return fail("append entry " + std::to_string(e.seq));
    bytes += input->size() + e.output.size();
  }
  st.update.Int(1, static_cast<std::int64_t>(entries.size()));
  st.update.Int(2, static_cast<std::int64_t>(bytes));
  st.update.Int(3, truncated ? 1 : 0);
  st.update.Int(4, run);
  if (step(st.update) != SQLITE_DONE) return fail("update run");
  if (sqlite3_changes(db_) != 1) {
    Rollback();
    return engine::NotFound("journal: no run " + std::to_string(run));
  }
  if (step(st.commit) != SQLITE_DONE) return fail("commit");
  return bytes;
}

Result<std::vector<JournalRun>> JournalStore::Runs() {
  // A journal opened read-only may still have the older layout (the setup in core_runs).
  Stmt q(db_, setups_apart_ ? "SELECT r.run, r.started_time, s.setup, r.entries, r.bytes, r.truncated "
                              "FROM core_runs r LEFT JOIN core_run_setups s ON s.run = r.run ORDER BY r.run"
                            : "SELECT run, started_time, setup, entries, bytes, truncated FROM core_runs ORDER BY run");
  if (!q.ok()) return Failed("list runs");
  std::vector<JournalRun> out;
  int rc;
  while ((rc = sqlite3_step(q.get())) == SQLITE_ROW) {
    JournalRun r;
    r.run = sqlite3_column_int64(q.get(), 0);
    r.started_time = sqlite3_column_double(q.get(), 1);
    r.setup = q.Col(2);
    r.entries = static_cast<std::uint64_t>(sqlite3_column_int64(q.get(), 3));
    r.bytes = static_cast<std::uint64_t>(sqlite3_column_int64(q.get(), 4));
    r.truncated = sqlite3_column_int64(q.get(), 5) != 0;
    out.push_back(std::move(r));
  }
  if (rc != SQLITE_DONE) return Failed("list runs");
  return out;
}

Result<std::vector<engine::JournalEntry>> JournalStore::Read(std::int64_t run, std::uint64_t after, int limit) {
  Stmt q(db_, "SELECT seq, time, kind, input, output FROM core_journal WHERE run = ? AND seq > ? ORDER BY seq LIMIT ?");
  if (!q.ok()) return Failed("read");
  q.Int(1, run);
  q.Int(2, static_cast<std::int64_t>(after));
  q.Int(3, limit);
  std::vector<engine::JournalEntry> out;
  int rc;
  while ((rc = sqlite3_step(q.get())) == SQLITE_ROW) {
    engine::JournalEntry e;
    e.seq = static_cast<std::uint64_t>(sqlite3_column_int64(q.get(), 0));
    const double time = sqlite3_column_double(q.get(), 1);
    const std::string kind_name = q.Col(2);
    auto kind = engine::ParseCoreInputKind(kind_name);
    if (!kind) return engine::IoError("stored journal entry " + std::to_string(e.seq) + " is corrupt: kind " + kind_name);
    auto input = DecodeCoreInput(*kind, time, q.Col(3));
    if (!input.ok()) return input.error();
    e.input = std::move(*input);
    e.output = q.Col(4);
    out.push_back(std::move(e));
  }
  if (rc != SQLITE_DONE) return Failed("read");
  return out;
}

}  // namespace dispatch::storage
