// SqliteStore test helpers: orders to store, opening a store, raw SQL on a second connection,
// and the fixture with a temporary database file (sqlite_store_test.cpp and
// sqlite_store_consistency_test.cpp).
#pragma once

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "storage/sqlite_store.h"
#include "tests/storage/temp_dir.h"

namespace dispatch::storage::testing {

inline engine::Order MakeOrder(const std::string& id, const std::string& client_id,
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

inline std::unique_ptr<SqliteStore> OpenOrDie(const std::string& path, SqliteOptions options = {}) {
  auto store = SqliteStore::Open(path, std::move(options));
  if (!store.ok()) ADD_FAILURE() << store.error().message;
  return store.ok() ? std::move(store).value() : nullptr;
}

// Runs one SQL query on its own connection and returns the first column of every row.
inline std::vector<std::string> RawQuery(const std::string& path, const std::string& sql) {
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
inline std::string RawExec(const std::string& path, const std::string& sql) {
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

}  // namespace dispatch::storage::testing
