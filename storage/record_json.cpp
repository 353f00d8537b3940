#include "storage/record_json.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>

#include "engine/common/fnv1a.h"

namespace dispatch::storage {

Error Corrupt(const char* what, const std::string& detail) {
  return engine::IoError(std::string("stored ") + what + " is corrupt: " + detail);
}

namespace {

using nlohmann::json;

// Order::stop_headings as [[stop index, radians], ...] in index order.
json HeadingsJson(const std::map<std::size_t, double>& headings) {
  json out = json::array();
  for (const auto& [k, heading] : headings) out.push_back(json::array({k, heading}));
  return out;
}

bool AllFinite(std::initializer_list<double> values) {
  for (double v : values) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

// Parses `text` and runs `read` on it, turning any JSON error into a Corrupt() error.
template <class F>
Status ReadJson(const char* what, const std::string& text, F&& read) {
  try {
    const json j = json::parse(text);
    return read(j);
  } catch (const json::exception& e) {
    return Corrupt(what, e.what());
  }
}

json MarksJson(const engine::OperatorMarks& m) {
  json j = json::object();
  if (!m.paused_by.empty()) j["paused_by"] = m.paused_by;
  if (!m.out_of_service_by.empty()) j["out_of_service_by"] = m.out_of_service_by;
  if (m.off_floor) j["off_floor"] = true;
  return j;
}

engine::OperatorMarks MarksOf(const json& j) {
  engine::OperatorMarks m;
  m.paused_by = j.value("paused_by", "");
  m.out_of_service_by = j.value("out_of_service_by", "");
  m.off_floor = j.value("off_floor", false);
  return m;
}

}  // namespace

std::string EncodeMarks(const engine::OperatorMarks& marks) { return MarksJson(marks).dump(); }

Result<engine::OperatorMarks> DecodeMarks(const std::string& text) {
  engine::OperatorMarks out;
  Status s = ReadJson("operator marks", text, [&](const json& j) -> Status {
    if (!j.is_object()) return Corrupt("operator marks", "not an object");
    out = MarksOf(j);
    return engine::Ok{};
  });
  if (!s.ok()) return s.error();
  return out;
}

const char* OrderEventTypeName(OrderEventType type) {
  switch (type) {
    case OrderEventType::kCreated: return "created";
    case OrderEventType::kStateChanged: return "state_changed";
    case OrderEventType::kProgress: return "progress";
  }
  return "unknown";
}

std::optional<OrderEventType> ParseOrderEventType(std::string_view name) {
  for (OrderEventType t :
       {OrderEventType::kCreated, OrderEventType::kStateChanged, OrderEventType::kProgress}) {
    if (name == OrderEventTypeName(t)) return t;
  }
  return std::nullopt;
}

std::string OrderContentHash(const engine::Order& order) {
  // Canonical encoding: a JSON array in a fixed field order; nlohmann prints doubles in
  // their shortest round-trip form, so equal values give equal text.
  // The client id goes in length-prefixed and raw (it may be any bytes).
  json content = json::array();
  content.push_back(order.priority);
  content.push_back(order.picks);
  content.push_back(order.drop);
  content.push_back(order.formation);
  content.push_back(order.work_time);
  content.push_back(order.release_time ? json(*order.release_time) : json(nullptr));
  // Only when given: the hashes of orders without headings stay what they were.
  if (!order.stop_headings.empty()) content.push_back(HeadingsJson(order.stop_headings));
  const std::string text =
      std::to_string(order.client_id.size()) + ":" + order.client_id + content.dump();
  return engine::Hex64(engine::Fnv1a64(text));
}

Result<std::string> EncodeOrderBody(const engine::Order& order) {
  if (!AllFinite({order.work_time, order.release_time.value_or(0.0)})) {
    return engine::InvalidArgument("order '" + order.id +
                                   "': work_time and release_time must be finite");
  }
  for (const auto& [k, heading] : order.stop_headings) {
    if (!std::isfinite(heading)) return engine::InvalidArgument("order '" + order.id + "': stop headings must be finite");
  }
  json j;
  j["picks"] = order.picks;
  j["drop"] = order.drop;
  j["work_time"] = order.work_time;
  j["release_time"] = order.release_time ? json(*order.release_time) : json(nullptr);
  if (!order.stop_headings.empty()) j["stop_headings"] = HeadingsJson(order.stop_headings);
  return j.dump();
}

Status DecodeOrderBody(const std::string& body, engine::Order& order) {
  return ReadJson("order", body, [&](const json& j) -> Status {
    order.picks = j.at("picks").get<std::vector<engine::PointId>>();
    order.drop = j.at("drop").get<engine::PointId>();
    order.work_time = j.at("work_time").get<double>();
    const json& release = j.at("release_time");
    order.release_time =
        release.is_null() ? std::nullopt : std::optional<double>(release.get<double>());
    order.stop_headings.clear();
    if (j.contains("stop_headings")) {  // [[stop index, radians], ...]; absent in older bodies
      for (const json& e : j.at("stop_headings")) {
        order.stop_headings[e.at(0).get<std::size_t>()] = e.at(1).get<double>();
      }
    }
    return engine::Ok{};
  });
}

Result<std::string> EncodeRobotBody(const engine::Robot& robot, const engine::OperatorMarks& marks) {
  const engine::Pose& p = robot.pose;
  if (!AllFinite({robot.diameter, robot.max_speed, p.position.x(), p.position.y(), p.heading,
                  robot.battery.value_or(0.0)})) {
    return engine::InvalidArgument("robot '" + robot.id + "': non-finite size, speed or pose");
  }
  json j;
  j["diameter"] = robot.diameter;
  if (robot.kind != engine::RobotKind::kDifferential) j["kind"] = engine::RobotKindName(robot.kind);
  j["max_speed"] = robot.max_speed;
  j["pose"] = {p.position.x(), p.position.y(), p.heading};
  j["current_point"] = robot.current_point;
  j["task_queue"] = robot.task_queue;
  j["battery"] = robot.battery ? json(*robot.battery) : json(nullptr);
  if (marks != engine::OperatorMarks{}) j["marks"] = MarksJson(marks);
  try {
    return j.dump();
  } catch (const json::exception& e) {
    return engine::InvalidArgument("robot '" + robot.id + "': " + e.what());
  }
}

Status DecodeRobotBody(const std::string& body, engine::Robot& robot, engine::OperatorMarks* marks) {
  return ReadJson("robot", body, [&](const json& j) -> Status {
    robot.diameter = j.at("diameter").get<double>();
    const std::string kind = j.value("kind", std::string("differential"));  // older bodies: none
    const auto parsed = engine::ParseRobotKind(kind);
    if (!parsed) return Corrupt("robot", "unknown kind '" + kind + "'");
    robot.kind = *parsed;
    robot.max_speed = j.at("max_speed").get<double>();
    const json& pose = j.at("pose");
    if (!pose.is_array() || pose.size() != 3) return Corrupt("robot", "pose is not [x, y, heading]");
    robot.pose.position = {pose[0].get<double>(), pose[1].get<double>()};
    robot.pose.heading = pose[2].get<double>();
    robot.current_point = j.at("current_point").get<engine::PointId>();
    robot.task_queue = j.at("task_queue").get<std::vector<std::string>>();
    const json& battery = j.at("battery");
    robot.battery =
        battery.is_null() ? std::nullopt : std::optional<double>(battery.get<double>());
    if (marks) {
      const auto m = j.find("marks");
      if (m != j.end() && !m->is_object()) return Corrupt("robot", "marks are not an object");
      *marks = m == j.end() ? engine::OperatorMarks{} : MarksOf(*m);
    }
    return engine::Ok{};
  });
}

Result<std::string> EncodeWaypoints(const std::vector<engine::Waypoint>& waypoints) {
  json list = json::array();
  for (const engine::Waypoint& w : waypoints) {
    if (!AllFinite({w.xy.x(), w.xy.y(), w.eta, w.dwell})) {
      return engine::InvalidArgument("waypoint " + std::to_string(w.seq) +
                                     ": non-finite position, eta or dwell");
    }
    // [seq, point, x, y, eta, action, dwell]: compact, plans can be long; a four-wheel-steer
    // robot's pose in a free space adds [heading, mode] (null for what is not set).
    json row = {w.seq, w.point, w.xy.x(), w.xy.y(), w.eta, engine::WaypointActionName(w.action), w.dwell};
    if (w.heading || w.mode) {
      if (w.heading && !std::isfinite(*w.heading)) {
        return engine::InvalidArgument("waypoint " + std::to_string(w.seq) + ": non-finite heading");
      }
      row.push_back(w.heading ? json(*w.heading) : json(nullptr));
      row.push_back(w.mode ? json(engine::MotionModeName(*w.mode)) : json(nullptr));
    }
    list.push_back(std::move(row));
  }
  return list.dump();
}

Result<std::vector<engine::Waypoint>> DecodeWaypoints(const std::string& text) {
  std::vector<engine::Waypoint> out;
  Status status = ReadJson("plan", text, [&](const json& list) -> Status {
    if (!list.is_array()) return Corrupt("plan", "waypoints are not a list");
    for (const json& row : list) {
      if (!row.is_array() || (row.size() != 7 && row.size() != 9)) {
        return Corrupt("plan", "waypoint is not a 7- or 9-tuple");
      }
      engine::Waypoint w;
      w.seq = row[0].get<int>();
      w.point = row[1].get<engine::PointId>();
      w.xy = {row[2].get<double>(), row[3].get<double>()};
      w.eta = row[4].get<double>();
      const auto action = engine::ParseWaypointAction(row[5].get<std::string>());
      if (!action) return Corrupt("plan", "unknown action " + row[5].dump());
      w.action = *action;
      w.dwell = row[6].get<double>();
      if (row.size() == 9) {
        if (!row[7].is_null()) w.heading = row[7].get<double>();
        if (!row[8].is_null()) {
          const auto mode = engine::ParseMotionMode(row[8].get<std::string>());
          if (!mode) return Corrupt("plan", "unknown motion mode " + row[8].dump());
          w.mode = *mode;
        }
      }
      out.push_back(w);
    }
    return engine::Ok{};
  });
  if (!status.ok()) return status.error();
  return out;
}

Result<std::string> EncodeStrings(const std::vector<std::string>& strings) {
  try {
    return json(strings).dump();
  } catch (const json::exception& e) {
    return engine::InvalidArgument(std::string("id list is not valid UTF-8: ") + e.what());
  }
}

Result<std::vector<std::string>> DecodeStrings(const std::string& text) {
  std::vector<std::string> out;
  Status status = ReadJson("id list", text, [&](const json& j) -> Status {
    out = j.get<std::vector<std::string>>();
    return engine::Ok{};
  });
  if (!status.ok()) return status.error();
  return out;
}

}  // namespace dispatch::storage
