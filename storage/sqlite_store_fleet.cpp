// SqliteStore: robots, their assignments and the map versions (opening, orders, events and
// transactions are in sqlite_store.cpp).
#include <algorithm>
#include <string>
#include <vector>

#include "storage/record_json.h"
#include "storage/sqlite_statement.h"
#include "storage/sqlite_store.h"

namespace dispatch::storage {
namespace {

constexpr const char* kRobotColumns =
    "id, state, kind, last_seen, last_acked_sequence, next_sequence, body";
constexpr const char* kAssignmentColumns =
    "robot_id, plan_id, order_ids, released_up_to, updated_time, waypoints";
constexpr const char* kMapColumns = "version, name, content_hash, source, recorded_time";

}  // namespace

// --- Robots ---------------------------------------------------------------------------

Status SqliteStore::UpsertRobot(const RobotRecord& r) {
  if (r.robot.id.empty()) return engine::InvalidArgument("a robot needs an id");
  if (!std::isfinite(r.last_seen) || !FitsInt64(r.last_acked_sequence) ||
      !FitsInt64(r.next_sequence)) {
    return engine::InvalidArgument("robot '" + r.robot.id +
                                   "': non-finite last_seen or sequence beyond 2^63");
  }
  Result<std::string> body = EncodeRobotBody(r.robot, r.marks);
  if (!body.ok()) return body.error();
  std::lock_guard lock(mu_);
  Status status = InTransaction([&]() -> Status {
    Result<Statement> stmt = Prepare(
        std::string("INSERT INTO robots (") + kRobotColumns +
        ") VALUES (?, ?, ?, ?, ?, ?, ?) ON CONFLICT(id) DO UPDATE SET state = excluded.state, "
        "kind = excluded.kind, last_seen = excluded.last_seen, "
        "last_acked_sequence = excluded.last_acked_sequence, "
        "next_sequence = excluded.next_sequence, body = excluded.body");
    if (!stmt.ok()) return stmt.error();
    return stmt.value()
        .Text(1, r.robot.id)
        .Text(2, engine::RobotStateName(r.robot.state))
        .Text(3, r.kind)
        .Real(4, r.last_seen)
        .Int(5, static_cast<std::int64_t>(r.last_acked_sequence))
        .Int(6, static_cast<std::int64_t>(r.next_sequence))
        .Text(7, body.value())
        .Run();
  });
  if (!status.ok()) return WithContext("save robot '" + r.robot.id + "'", status.error());
  return status;
}

namespace {
template <class Stmt>
Result<RobotRecord> ReadRobot(Stmt& s) {
  RobotRecord r;
  r.robot.id = s.ColText(0);
  const auto state = engine::ParseRobotState(s.ColText(1));
  if (!state) return Corrupt("state of robot '" + r.robot.id + "'");
  r.robot.state = *state;
  r.kind = s.ColText(2);
  r.last_seen = s.ColReal(3);
  r.last_acked_sequence = static_cast<std::uint64_t>(s.ColInt(4));
  r.next_sequence = static_cast<std::uint64_t>(s.ColInt(5));
  if (Status st = DecodeRobotBody(s.ColText(6), r.robot, &r.marks); !st.ok()) {
    return WithContext("robot '" + r.robot.id + "'", st.error());
  }
  return r;
}

template <class Stmt>
Result<AssignmentRecord> ReadAssignment(Stmt& s) {
  AssignmentRecord a;
  a.robot_id = s.ColText(0);
  a.plan_id = static_cast<std::uint64_t>(s.ColInt(1));
  Result<std::vector<std::string>> orders = DecodeStrings(s.ColText(2));
  if (!orders.ok()) return WithContext("assignment of '" + a.robot_id + "'", orders.error());
  a.order_ids = std::move(orders).value();
  a.released_up_to = s.ColInt(3);
  a.updated_time = s.ColReal(4);
  Result<std::vector<engine::Waypoint>> waypoints = DecodeWaypoints(s.ColText(5));
  if (!waypoints.ok()) return WithContext("assignment of '" + a.robot_id + "'", waypoints.error());
  a.plan.robot_id = a.robot_id;
  a.plan.waypoints = std::move(waypoints).value();
  return a;
}

template <class Stmt>
MapVersion ReadMapVersion(Stmt& s) {
  MapVersion m;
  m.version = s.ColInt(0);
  m.name = s.ColText(1);
  m.content_hash = s.ColText(2);
  m.source = s.ColText(3);
  m.recorded_time = s.ColReal(4);
  return m;
}
}  // namespace

Result<RobotRecord> SqliteStore::GetRobot(const std::string& robot_id) {
  std::lock_guard lock(mu_);
  Result<Statement> stmt =
      Prepare(std::string("SELECT ") + kRobotColumns + " FROM robots WHERE id = ?");
  if (!stmt.ok()) return stmt.error();
  stmt.value().Text(1, robot_id);
  Result<bool> row = stmt.value().Step();
  if (!row.ok()) return row.error();
  if (!*row) return engine::NotFound("no robot with id '" + robot_id + "'");
  return ReadRobot(stmt.value());
}

Result<std::vector<RobotRecord>> SqliteStore::ListRobots() {
  std::lock_guard lock(mu_);
  Result<Statement> stmt =
      Prepare(std::string("SELECT ") + kRobotColumns + " FROM robots ORDER BY id");
  if (!stmt.ok()) return stmt.error();
  std::vector<RobotRecord> robots;
  for (;;) {
    Result<bool> row = stmt.value().Step();
    if (!row.ok()) return row.error();
    if (!*row) break;
    Result<RobotRecord> r = ReadRobot(stmt.value());
    if (!r.ok()) return r.error();
    robots.push_back(std::move(r).value());
  }
  return robots;
}

// --- Assignments ----------------------------------------------------------------------

Status SqliteStore::SaveAssignment(const AssignmentRecord& a) {
  if (a.robot_id.empty()) return engine::InvalidArgument("an assignment needs a robot id");
  if (!a.plan.robot_id.empty() && a.plan.robot_id != a.robot_id) {
    return engine::InvalidArgument("assignment of '" + a.robot_id + "' holds the plan of '" +
                                   a.plan.robot_id + "'");
  }
  if (!FitsInt64(a.plan_id) || !std::isfinite(a.updated_time)) {
    return engine::InvalidArgument("assignment of '" + a.robot_id +
                                   "': plan id beyond 2^63 or non-finite time");
  }
  Result<std::string> waypoints = EncodeWaypoints(a.plan.waypoints);
  if (!waypoints.ok()) return WithContext("assignment of '" + a.robot_id + "'", waypoints.error());
  Result<std::string> orders = EncodeStrings(a.order_ids);
  if (!orders.ok()) return orders.error();
  std::lock_guard lock(mu_);
  Status status = InTransaction([&]() -> Status {
    Result<Statement> stmt = Prepare(
        std::string("INSERT INTO assignments (") + kAssignmentColumns +
        ") VALUES (?, ?, ?, ?, ?, ?) ON CONFLICT(robot_id) DO UPDATE SET "
        "plan_id = excluded.plan_id, order_ids = excluded.order_ids, "
        "released_up_to = excluded.released_up_to, updated_time = excluded.updated_time, "
        "waypoints = excluded.waypoints");
    if (!stmt.ok()) return stmt.error();
    return stmt.value()
        .Text(1, a.robot_id)
        .Int(2, static_cast<std::int64_t>(a.plan_id))
        .Text(3, orders.value())
        .Int(4, a.released_up_to)
        .Real(5, a.updated_time)
        .Text(6, waypoints.value())
        .Run();
  });
  if (!status.ok()) return WithContext("save assignment of '" + a.robot_id + "'", status.error());
  return status;
}

Result<AssignmentRecord> SqliteStore::GetAssignment(const std::string& robot_id) {
  std::lock_guard lock(mu_);
  Result<Statement> stmt = Prepare(std::string("SELECT ") + kAssignmentColumns +
                                   " FROM assignments WHERE robot_id = ?");
  if (!stmt.ok()) return stmt.error();
  stmt.value().Text(1, robot_id);
  Result<bool> row = stmt.value().Step();
  if (!row.ok()) return row.error();
  if (!*row) return engine::NotFound("robot '" + robot_id + "' has no assignment");
  return ReadAssignment(stmt.value());
}

Result<std::vector<AssignmentRecord>> SqliteStore::ListAssignments() {
  std::lock_guard lock(mu_);
  Result<Statement> stmt = Prepare(std::string("SELECT ") + kAssignmentColumns +
                                   " FROM assignments ORDER BY robot_id");
  if (!stmt.ok()) return stmt.error();
  std::vector<AssignmentRecord> out;
  for (;;) {
    Result<bool> row = stmt.value().Step();
    if (!row.ok()) return row.error();
    if (!*row) break;
    Result<AssignmentRecord> a = ReadAssignment(stmt.value());
    if (!a.ok()) return a.error();
    out.push_back(std::move(a).value());
  }
  return out;
}

Status SqliteStore::DeleteAssignment(const std::string& robot_id) {
  std::lock_guard lock(mu_);
  return InTransaction([&]() -> Status {
    Result<Statement> stmt = Prepare("DELETE FROM assignments WHERE robot_id = ?");
    if (!stmt.ok()) return stmt.error();
    if (Status run = stmt.value().Text(1, robot_id).Run(); !run.ok()) return run;
    if (sqlite3_changes(db_) == 0) {
      return engine::NotFound("robot '" + robot_id + "' has no assignment");
    }
    return engine::Ok{};
  });
}

// --- Map versions ---------------------------------------------------------------------

Result<MapVersion> SqliteStore::RecordMapVersion(const MapVersion& map) {
  if (map.name.empty() || map.content_hash.empty()) {
    return engine::InvalidArgument("a map version needs a name and a content hash");
  }
  if (!std::isfinite(map.recorded_time)) {
    return engine::InvalidArgument("map version time must be finite");
  }
  std::lock_guard lock(mu_);
  std::optional<MapVersion> out;
  Status status = InTransaction([&]() -> Status {
    Result<MapVersion> latest = LatestMapVersion();
    if (latest.ok() && latest->name == map.name && latest->content_hash == map.content_hash) {
      out = latest.value();
      return engine::Ok{};
    }
    if (latest.ok() && latest->name == map.name &&
        std::find(map.also_known_as.begin(), map.also_known_as.end(), latest->content_hash) !=
            map.also_known_as.end()) {  // the same map under an older hash: re-tagged
      Result<Statement> update = Prepare("UPDATE map_versions SET content_hash = ? WHERE version = ?");
      if (!update.ok()) return update.error();
      Status run = update.value().Text(1, map.content_hash).Int(2, latest->version).Run();
      if (!run.ok()) return run;
      out = latest.value();
      out->content_hash = map.content_hash;
      return engine::Ok{};
    }
    if (!latest.ok() && latest.error().code != engine::ErrorCode::kNotFound) {
      return latest.error();
    }
    Result<Statement> stmt = Prepare(
        "INSERT INTO map_versions (name, content_hash, source, recorded_time) "
        "VALUES (?, ?, ?, ?)");
    if (!stmt.ok()) return stmt.error();
    Status run = stmt.value()
                     .Text(1, map.name)
                     .Text(2, map.content_hash)
                     .Text(3, map.source)
                     .Real(4, map.recorded_time)
                     .Run();
    if (!run.ok()) return run;
    out = map;
    out->version = sqlite3_last_insert_rowid(db_);
    return engine::Ok{};
  });
  if (!status.ok()) return WithContext("record map version", status.error());
  return std::move(*out);
}

Result<MapVersion> SqliteStore::LatestMapVersion() {
  std::lock_guard lock(mu_);
  Result<Statement> stmt = Prepare(std::string("SELECT ") + kMapColumns +
                                   " FROM map_versions ORDER BY version DESC LIMIT 1");
  if (!stmt.ok()) return stmt.error();
  Result<bool> row = stmt.value().Step();
  if (!row.ok()) return row.error();
  if (!*row) return engine::NotFound("no map version recorded");
  return ReadMapVersion(stmt.value());
}

}  // namespace dispatch::storage
