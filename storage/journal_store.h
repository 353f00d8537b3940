// JournalStore: the dispatch core's journal in the service's SQLite file (issue 15 §4), on a
// connection of its own so that journal writes never wait behind, or roll back with, the
// store's transactions.
//
// Tables (created here if missing): core_runs (one row per dispatchd start: its entry and byte
// counts, whether recording stopped at the size limit), core_run_setups (run, setup: written
// once) and core_journal (run, seq, time, kind, input, output). A journal of the older layout
// (the setup in core_runs, core_journal WITHOUT ROWID) is moved to this one when opened for
// writing, and read as it is when opened read-only.
//
// Retention: StartRun keeps the newest `keep_runs` runs, the new one included, and deletes the
// others; within a run nothing is deleted (a replay starts at the run's first entry).
//
// Errors: kIoError (the database failed; an Append writes all its entries or none),
// kNotFound (unknown run). Not thread-safe: one user at a time (the service's journal worker,
// or dispatch-sim replay).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "engine/common/result.h"
#include "engine/dispatch/core_journal.h"

struct sqlite3;

namespace dispatch::storage {

using engine::Result;
using engine::Status;

struct JournalRun {
  std::int64_t run = 0;
  double started_time = 0.0;  // Unix seconds when the run began
  std::string setup;          // EncodeRunSetup
  std::uint64_t entries = 0;
  std::uint64_t bytes = 0;    // input + output text written
  bool truncated = false;     // recording stopped at the size limit
};

class JournalStore {
 public:
  // Opens (read_only: an existing file, without creating the tables) the SQLite file at path.
  static Result<std::unique_ptr<JournalStore>> Open(const std::string& path, bool read_only = false);
  ~JournalStore();
  JournalStore(const JournalStore&) = delete;
  JournalStore& operator=(const JournalStore&) = delete;

  // A new run; deletes all but the newest keep_runs - 1 earlier runs (keep_runs >= 1).
  Result<std::int64_t> StartRun(double started_time, const std::string& setup, int keep_runs);
  // Appends entries (in seq order) in one transaction; `truncated` marks the run as stopped.
  // Returns the bytes written (input and output text).
  Result<std::uint64_t> Append(std::int64_t run, const std::vector<engine::JournalEntry>& entries, bool truncated = false);
  // Every run, oldest first.
  Result<std::vector<JournalRun>> Runs();
  // Up to `limit` entries of `run` with seq > after, in seq order.
  Result<std::vector<engine::JournalEntry>> Read(std::int64_t run, std::uint64_t after, int limit);

 private:
  explicit JournalStore(sqlite3* db);
  class Stmt;
  Status Exec(const char* sql);
  bool HasTable(const char* name);
  Status Upgrade();  // creates the tables, or moves an older layout over (see above)
  void Rollback() { static_cast<void>(Exec("ROLLBACK")); }  // after a failure: nothing else to do
  engine::Error Failed(const std::string& what) const;

  sqlite3* db_;
  struct AppendStatements;
  std::unique_ptr<AppendStatements> append_;  // prepared by the first Append
  bool setups_apart_ = true;  // false: a read-only journal of the older layout
};

}  // namespace dispatch::storage
