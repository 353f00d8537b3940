// The SQLite schema as an ordered list of migrations (SPEC §4 "schema migrations").
//
// Migration i has version i + 1. A database records the versions it has applied in
// `schema_migrations`; SqliteStore::Open applies the missing ones in order, each in its own
// transaction together with its `schema_migrations` row. Released migrations are never
// edited: a schema change is a new migration appended to the list. Constant data.
#pragma once

#include <span>

namespace dispatch::storage {

struct Migration {
  int version;
  const char* name;
  const char* sql;  // one or more statements
};

// All migrations, in version order (versions 1, 2, 3, ...).
std::span<const Migration> Migrations();

}  // namespace dispatch::storage
