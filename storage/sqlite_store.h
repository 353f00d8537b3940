// SqliteStore: the Store on an on-disk SQLite database (SPEC §4 "Storage").
//
// Open() creates the file if needed, switches it to WAL, sets the busy timeout and
// synchronous mode, and applies the pending schema migrations (storage/migrations.h) in
// version order, each in its own transaction; a database newer than this binary, or a file
// that is not SQLite, is a clear error. Every write runs in one transaction (BEGIN
// IMMEDIATE ... COMMIT, or a SAVEPOINT inside RunInTransaction); with the default
// synchronous = FULL a returned OK survives a process kill and a power loss.
//
// Layout: queried fields in columns, the rest of a record as JSON (storage/record_json.h).
// Order events are append-only (triggers reject UPDATE and DELETE).
//
// Thread safety: one SqliteStore is one SQLite connection; all its methods are thread-safe
// and serialised by one mutex (RunInTransaction holds it for the whole body). For reads that
// must not wait behind writes, open a second SqliteStore on the same file: in WAL readers
// and the writer do not block each other, and readers see only committed data. Several
// processes may open the file; writers wait up to busy_timeout for each other.
#pragma once

#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <unordered_map>

#include "storage/store.h"

struct sqlite3;
struct sqlite3_stmt;

namespace dispatch::storage {

struct SqliteOptions {
  // How long a write waits for another connection's write lock, milliseconds.
  int busy_timeout_ms = 5000;
  // true: PRAGMA synchronous = FULL (a commit survives power loss). false: NORMAL (a commit
  // survives a process crash; the last commits may be lost on power loss). WAL either way.
  bool full_sync = true;
  // Test seam: called before every data-changing statement (INSERT/UPDATE/DELETE) with its
  // SQL; an error fails that statement as if SQLite had failed it, and the surrounding write
  // is rolled back like after any other failure. Unset in production.
  std::function<Status(std::string_view sql)> before_write;
};

class SqliteStore final : public Store {
 public:
  // Opens (creating if missing) and migrates the database at `path`. Errors (kIoError)
  // name the path and what failed: cannot open, not a database, newer schema, migration N.
  static Result<std::unique_ptr<SqliteStore>> Open(const std::string& path,
                                                   SqliteOptions options = {});
  ~SqliteStore() override;
  SqliteStore(const SqliteStore&) = delete;
  SqliteStore& operator=(const SqliteStore&) = delete;

  const std::string& path() const { return path_; }
  // The schema version after Open (the highest applied migration).
  int schema_version() const { return schema_version_; }

  Result<InsertOrderResult> InsertOrder(const engine::Order& order, const std::string& actor) override;
  Result<OrderRecord> GetOrder(const std::string& order_id) override;
  Result<OrderRecord> GetOrderByClientId(const std::string& client_id) override;
  Result<OrderPage> ListOrders(const OrderQuery& query) override;
  Result<OrderEvent> TransitionOrder(const OrderTransition& transition) override;
  Result<OrderEvent> AppendProgress(const std::string& order_id, double time,
                                    const std::string& detail) override;
  Result<std::vector<OrderEvent>> ListEvents(const EventQuery& query) override;

  Status UpsertRobot(const RobotRecord& robot) override;
  Result<RobotRecord> GetRobot(const std::string& robot_id) override;
  Result<std::vector<RobotRecord>> ListRobots() override;

  Status SaveAssignment(const AssignmentRecord& assignment) override;
  Result<AssignmentRecord> GetAssignment(const std::string& robot_id) override;
  Result<std::vector<AssignmentRecord>> ListAssignments() override;
  Status DeleteAssignment(const std::string& robot_id) override;

  Result<MapVersion> RecordMapVersion(const MapVersion& map) override;
  Result<MapVersion> LatestMapVersion() override;

  Status RunInTransaction(const std::function<Status(Store&)>& body) override;

 private:
  class Statement;
  SqliteStore(std::string path, SqliteOptions options, sqlite3* db);

  Status Configure();
  Status Migrate();
  Error SqliteError(std::string_view what) const;
  Result<Statement> Prepare(const std::string& sql);
  Status Exec(const char* sql);
  // Runs `write` in a transaction (or a savepoint when one is open); commits on OK, rolls
  // back on error. Caller holds mu_.
  Status InTransaction(const std::function<Status()>& write);
  Result<OrderRecord> ReadOrder(Statement& stmt);
  Result<OrderEvent> ReadEvent(Statement& stmt);
  Result<OrderEvent> InsertEvent(const OrderEvent& event);
  Result<OrderRecord> FindOrder(const char* column, const std::string& key);

  const std::string path_;
  const SqliteOptions options_;
  int schema_version_ = 0;
  std::recursive_mutex mu_;  // guards db_, statements_, tx_depth_
  sqlite3* db_;
  std::unordered_map<std::string, sqlite3_stmt*> statements_;  // prepared once, reused
  int tx_depth_ = 0;  // open transactions/savepoints on db_
  bool hooks_enabled_ = false;  // before_write applies after Open's migrations
};

}  // namespace dispatch::storage
