#include "storage/migrations.h"

namespace dispatch::storage {
namespace {

// Times are dispatcher seconds (REAL). `seq` gives orders their insertion order (paging);
// AUTOINCREMENT keeps ids increasing and never reused, also after deletes.
constexpr Migration kMigrations[] = {
    {1, "orders and the order event journal", R"sql(
CREATE TABLE orders (
  seq          INTEGER PRIMARY KEY AUTOINCREMENT,
  id           TEXT NOT NULL UNIQUE,
  client_id    TEXT NOT NULL UNIQUE,
  state        TEXT NOT NULL,
  priority     INTEGER NOT NULL,
  formation    INTEGER NOT NULL,
  created_time REAL NOT NULL,
  updated_time REAL NOT NULL,
  content_hash TEXT NOT NULL,
  robots       TEXT NOT NULL,      -- JSON array of robot ids, leader first
  reason       TEXT NOT NULL,
  body         TEXT NOT NULL       -- JSON: picks, drop, work_time, release_time
);
CREATE INDEX orders_by_state ON orders(state, seq);
CREATE TABLE order_events (
  id             INTEGER PRIMARY KEY AUTOINCREMENT,
  order_id       TEXT NOT NULL REFERENCES orders(id),
  type           TEXT NOT NULL,
  state          TEXT NOT NULL,
  previous_state TEXT,
  time           REAL NOT NULL,
  robots         TEXT NOT NULL,    -- JSON array of robot ids
  detail         TEXT NOT NULL
);
CREATE INDEX order_events_by_order ON order_events(order_id, id);
CREATE TRIGGER order_events_no_update BEFORE UPDATE ON order_events
BEGIN SELECT RAISE(ABORT, 'order_events is append-only'); END;
CREATE TRIGGER order_events_no_delete BEFORE DELETE ON order_events
BEGIN SELECT RAISE(ABORT, 'order_events is append-only'); END;
)sql"},
    {2, "robots and their current assignments", R"sql(
CREATE TABLE robots (
  id                  TEXT PRIMARY KEY,
  state               TEXT NOT NULL,
  kind                TEXT NOT NULL,
  last_seen           REAL NOT NULL,
  last_acked_sequence INTEGER NOT NULL,
  next_sequence       INTEGER NOT NULL,
  body                TEXT NOT NULL  -- JSON: diameter, max_speed, pose, point, queue, battery
);
CREATE TABLE assignments (
  robot_id       TEXT PRIMARY KEY,
  plan_id        INTEGER NOT NULL,
  order_ids      TEXT NOT NULL,    -- JSON array, execution order
  released_up_to INTEGER NOT NULL,
  updated_time   REAL NOT NULL,
  waypoints      TEXT NOT NULL     -- JSON: [[seq, point, x, y, eta, action, dwell], ...]
);
)sql"},
    {3, "map versions", R"sql(
CREATE TABLE map_versions (
  version       INTEGER PRIMARY KEY AUTOINCREMENT,
  name          TEXT NOT NULL,
  content_hash  TEXT NOT NULL,
  source        TEXT NOT NULL,
  recorded_time REAL NOT NULL
);
)sql"},
    {4, "metres driven for each order", R"sql(
ALTER TABLE orders ADD COLUMN distance REAL NOT NULL DEFAULT 0;
)sql"},
    {5, "who made each order event (the token's name)", R"sql(
ALTER TABLE order_events ADD COLUMN actor TEXT NOT NULL DEFAULT '';
)sql"},
};

}  // namespace

std::span<const Migration> Migrations() { return kMigrations; }

}  // namespace dispatch::storage
