// SqliteStore's internals shared by its source files (sqlite_store.cpp: opening, helpers,
// orders and events, transactions; sqlite_store_fleet.cpp: robots, assignments, map
// versions): the prepared-statement wrapper and error helpers. Not part of the interface.
#pragma once

#include <sqlite3.h>

#include <cstdint>
#include <limits>
#include <string>
#include <utility>

#include "storage/sqlite_store.h"

namespace dispatch::storage {

inline Error FailedPrecondition(std::string message) {
  return {engine::ErrorCode::kFailedPrecondition, std::move(message)};
}

inline Error Corrupt(const std::string& what) { return engine::IoError("stored " + what + " is corrupt"); }

inline Error WithContext(const std::string& context, const Error& error) {
  return {error.code, context + ": " + error.message};
}

inline bool FitsInt64(std::uint64_t v) {
  return v <= static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
}

// A cached prepared statement in use: binds by 1-based index, steps, reads columns, and
// resets itself (bindings cleared) when it goes out of scope so the cache can reuse it.
class SqliteStore::Statement {
 public:
  Statement(SqliteStore* store, sqlite3_stmt* stmt) : store_(store), stmt_(stmt) {}
  Statement(Statement&& other) noexcept
      : store_(other.store_), stmt_(std::exchange(other.stmt_, nullptr)),
        bind_rc_(other.bind_rc_) {}
  Statement& operator=(Statement&&) = delete;
  ~Statement() {
    if (stmt_ != nullptr) {
      sqlite3_reset(stmt_);
      sqlite3_clear_bindings(stmt_);
    }
  }

  Statement& Text(int i, const std::string& s) {
    return Check(sqlite3_bind_text(stmt_, i, s.data(), static_cast<int>(s.size()),
                                   SQLITE_TRANSIENT));
  }
  Statement& Int(int i, std::int64_t v) { return Check(sqlite3_bind_int64(stmt_, i, v)); }
  Statement& Real(int i, double v) { return Check(sqlite3_bind_double(stmt_, i, v)); }
  Statement& Null(int i) { return Check(sqlite3_bind_null(stmt_, i)); }

  // true: a row is ready; false: done. Data-changing statements pass the test hook first.
  Result<bool> Step() {
    if (bind_rc_ != SQLITE_OK) return store_->SqliteError("bind parameters");
    if (!stepped_ && store_->hooks_enabled_ && store_->options_.before_write &&
        sqlite3_stmt_readonly(stmt_) == 0) {
      Status hook = store_->options_.before_write(sqlite3_sql(stmt_));
      if (!hook.ok()) return hook.error();
    }
    stepped_ = true;
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    return store_->SqliteError(sqlite3_sql(stmt_));
  }
  // Steps to the end (statements without result rows).
  Status Run() {
    for (;;) {
      Result<bool> row = Step();
      if (!row.ok()) return row.error();
      if (!*row) return engine::Ok{};
    }
  }

  std::string ColText(int i) const {
    const auto* p = reinterpret_cast<const char*>(sqlite3_column_text(stmt_, i));
    return p == nullptr ? std::string() : std::string(p, static_cast<std::size_t>(
                                                             sqlite3_column_bytes(stmt_, i)));
  }
  std::int64_t ColInt(int i) const { return sqlite3_column_int64(stmt_, i); }
  double ColReal(int i) const { return sqlite3_column_double(stmt_, i); }
  bool ColNull(int i) const { return sqlite3_column_type(stmt_, i) == SQLITE_NULL; }

 private:
  Statement& Check(int rc) {
    if (rc != SQLITE_OK && bind_rc_ == SQLITE_OK) bind_rc_ = rc;
    return *this;
  }

  SqliteStore* store_;
  sqlite3_stmt* stmt_;
  int bind_rc_ = SQLITE_OK;
  bool stepped_ = false;
};

}  // namespace dispatch::storage
