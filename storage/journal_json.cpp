#include "storage/journal_json.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "engine/routing/route_table.h"
#include "storage/record_json.h"

namespace dispatch::storage {
namespace {

using nlohmann::json;
using engine::CoreInput;

// Runs `fn` (which may throw json errors) and maps them to `error`.
template <class T, class F>
Result<T> Guard(const char* what, bool decoding, F&& fn) {
  try {
    return fn();
  } catch (const std::exception& e) {  // json errors, and Embedded's
    if (decoding) return Corrupt(what, e.what());
    return engine::InvalidArgument(std::string(what) + ": " + e.what());
  }
}

json Embedded(const Result<std::string>& text) {
  if (!text.ok()) throw std::invalid_argument(text.error().message);
  return json::parse(*text);
}

Result<json> OrderJson(const engine::Order& o) {
  auto body = EncodeOrderBody(o);
  if (!body.ok()) return body.error();
  json j;
  j["id"] = o.id;
  j["client_id"] = o.client_id;
  j["priority"] = o.priority;
  j["formation"] = o.formation;
  j["created"] = o.created_time;
  j["state"] = engine::OrderStateName(o.state);
  j["body"] = json::parse(*body);
  return j;
}

Result<engine::Order> OrderOf(const json& j) {
  engine::Order o;
  o.id = j.at("id").get<std::string>();
  o.client_id = j.at("client_id").get<std::string>();
  o.priority = j.at("priority").get<int>();
  o.formation = j.at("formation").get<bool>();
  o.created_time = j.at("created").get<double>();
  auto state = engine::ParseOrderState(j.at("state").get<std::string>());
  if (!state) return Corrupt("journal order", "unknown state");
  o.state = *state;
  if (auto s = DecodeOrderBody(j.at("body").dump(), o); !s.ok()) return s.error();
  return o;
}

Result<json> RobotJson(const engine::Robot& r) {
  auto body = EncodeRobotBody(r);
  if (!body.ok()) return body.error();
  return json{{"id", r.id}, {"state", engine::RobotStateName(r.state)}, {"body", json::parse(*body)}};
}

Result<engine::Robot> RobotOf(const json& j) {
  engine::Robot r;
  r.id = j.at("id").get<std::string>();
  auto state = engine::ParseRobotState(j.at("state").get<std::string>());
  if (!state) return Corrupt("journal robot", "unknown state");
  r.state = *state;
  if (auto s = DecodeRobotBody(j.at("body").dump(), r); !s.ok()) return s.error();
  return r;
}

// A robot may report anything (NaN, infinities: the core ignores such poses), and the journal
// keeps what the core was given: non-finite numbers as the strings "nan", "inf", "-inf".
json Num(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return v;
}
double NumOf(const json& j) {
  if (!j.is_string()) return j.get<double>();
  const std::string s = j.get<std::string>();
  if (s == "nan") return std::numeric_limits<double>::quiet_NaN();
  if (s == "inf") return std::numeric_limits<double>::infinity();
  if (s == "-inf") return -std::numeric_limits<double>::infinity();
  throw std::invalid_argument("not a number: " + s);
}

json PoseJson(const engine::Pose& p) { return json{Num(p.position.x()), Num(p.position.y()), Num(p.heading)}; }
engine::Pose PoseOf(const json& j) {
  engine::Pose p;
  p.position = {NumOf(j.at(0)), NumOf(j.at(1))};
  p.heading = NumOf(j.at(2));
  return p;
}

const char* HeadOnName(engine::HeadOnPolicy p) {
  switch (p) {
    case engine::HeadOnPolicy::kChooseFaster: return "choose_faster";
    case engine::HeadOnPolicy::kAlwaysWait: return "always_wait";
    case engine::HeadOnPolicy::kAlwaysReplan: return "always_replan";
  }
  return "?";
}

}  // namespace

Result<std::string> EncodeRunSetup(const RunSetup& s) {
  return Guard<std::string>("run setup", false, [&]() -> Result<std::string> {
    const engine::AllocationConfig& a = s.allocation;
    const engine::TrafficControllerConfig& t = s.core.traffic;
    json j;
    j["version"] = s.version;
    j["map_source"] = s.map_source;
    j["map"] = json::parse(s.map_json);
    j["strategy"] = s.strategy;
    j["allocation"] = {{"alpha", a.alpha},
                       {"beta", a.beta},
                       {"zeta", a.zeta},
                       {"sample_step", a.sample_step},
                       {"speed", a.speed},
                       {"hold_seconds", a.hold_seconds},
                       {"price_every_bid_up_to", a.price_every_bid_up_to},
                       {"max_queue", a.max_queue},
                       {"formation_max_queue", a.formation_max_queue},
                       {"work_time_override", a.work_time_override ? json(*a.work_time_override) : json(nullptr)},
                       {"drop_time", a.drop_time ? json(*a.drop_time) : json(nullptr)},
                       {"bucket_seconds", a.traffic.bucket_seconds},
                       {"origin_time", a.traffic.origin_time},
                       {"zone_cell_size", a.traffic.zone_cell_size},
                       {"formation_side", a.formation.side},
                       {"formation_base_angle", a.formation.base_angle},
                       {"formation_max_rotation_step", a.formation.max_rotation_step},
                       {"planner", engine::PlannerName(a.planner)},
                       {"windows_body_length", a.windows.body_length},
                       {"windows_headway_s", a.windows.headway_s},
                       {"turn_time", a.turn_time},
                       {"routing", engine::RoutingName(a.routing)},
                       {"heat_period", a.heat_period}};
    j["core"] = {{"robot_snap_tolerance", s.core.robot_snap_tolerance},
                 {"traffic_control", s.core.traffic_control},
                 {"one_formation_per_pick", s.core.one_formation_per_pick},
                 {"blocked_recovery", s.core.blocked_recovery},
                 {"max_give_backs", s.core.max_give_backs},
                 {"speed", t.speed},
                 {"point_clearance", t.point_clearance},
                 {"t_w1", t.t_w1},
                 {"t_w2", t.t_w2},
                 {"blocked_after", t.blocked_after},
                 {"max_envelope", t.max_envelope},
                 {"intersection_grants", t.intersection_grants},
                 {"head_on", HeadOnName(t.head_on)},
                 {"priority_by_release", t.priority_by_release},
                 {"head_on_priority", t.head_on_priority},
                 {"head_on_give_way", t.head_on_give_way},
                 {"execution", engine::PlanExecutionName(t.execution)}};
    j["route_cache_bytes"] = s.route_cache_bytes;
    j["route_table"] = s.route_table;
    j["time_scale"] = s.time_scale;
    return j.dump();
  });
}

Result<RunSetup> DecodeRunSetup(const std::string& text) {
  return Guard<RunSetup>("run setup", true, [&]() -> Result<RunSetup> {
    const json j = json::parse(text);
    RunSetup s;
    s.version = j.at("version").get<std::string>();
    if (s.version != "1") return Corrupt("run setup", "unknown version " + s.version);
    s.map_source = j.at("map_source").get<std::string>();
    s.map_json = j.at("map").dump();
    s.strategy = j.at("strategy").get<std::string>();
    const json& a = j.at("allocation");
    engine::AllocationConfig& c = s.allocation;
    c.alpha = a.at("alpha").get<double>();
    c.beta = a.at("beta").get<double>();
    c.zeta = a.at("zeta").get<double>();
    c.sample_step = a.at("sample_step").get<double>();
    c.speed = a.at("speed").get<double>();
    c.hold_seconds = a.at("hold_seconds").get<double>();
    c.price_every_bid_up_to = a.at("price_every_bid_up_to").get<std::size_t>();
    c.max_queue = a.value("max_queue", std::size_t{0});
    c.formation_max_queue = a.value("formation_max_queue", std::size_t{0});  // older runs had no limit
    if (!a.at("work_time_override").is_null()) c.work_time_override = a.at("work_time_override").get<double>();
    c.traffic.bucket_seconds = a.at("bucket_seconds").get<double>();
    c.traffic.origin_time = a.at("origin_time").get<double>();
    c.traffic.zone_cell_size = a.at("zone_cell_size").get<double>();
    c.formation.side = a.at("formation_side").get<double>();
    c.formation.base_angle = a.at("formation_base_angle").get<double>();
    c.formation.max_rotation_step = a.at("formation_max_rotation_step").get<double>();
    // Journals before the planners were selectable ran the rules.
    const std::string planner = a.value("planner", std::string("rules"));
    const auto kind = engine::ParsePlanner(planner);
    if (!kind) return Corrupt("run setup", "unknown planner " + planner);
    c.planner = *kind;
    c.windows.body_length = a.value("windows_body_length", c.windows.body_length);
    c.windows.headway_s = a.value("windows_headway_s", c.windows.headway_s);
    c.turn_time = a.value("turn_time", 0.0);
    // Journals before drop_time worked each order's t_w at its drop (null, or no key).
    c.drop_time.reset();
    if (a.contains("drop_time") && !a.at("drop_time").is_null()) c.drop_time = a.at("drop_time").get<double>();
    const std::string routing = a.value("routing", std::string("floyd"));
    const auto route_kind = engine::ParseRouting(routing);
    if (!route_kind) return Corrupt("run setup", "unknown routing " + routing);
    c.routing = *route_kind;
    c.heat_period = a.value("heat_period", c.heat_period);
    const json& k = j.at("core");
    s.core.robot_snap_tolerance = k.at("robot_snap_tolerance").get<double>();
    s.core.traffic_control = k.at("traffic_control").get<bool>();
    s.core.one_formation_per_pick = k.value("one_formation_per_pick", false);
    s.core.blocked_recovery = k.value("blocked_recovery", 0.0);  // journals before it: never
    s.core.max_give_backs = k.value("max_give_backs", 0);         // journals before it: no limit
    engine::TrafficControllerConfig& t = s.core.traffic;
    t.speed = k.at("speed").get<double>();
    t.point_clearance = k.at("point_clearance").get<double>();
    t.t_w1 = k.at("t_w1").get<double>();
    t.t_w2 = k.at("t_w2").get<double>();
    t.blocked_after = k.at("blocked_after").get<double>();
    t.max_envelope = k.at("max_envelope").get<double>();
    t.intersection_grants = k.at("intersection_grants").get<bool>();
    t.priority_by_release = k.value("priority_by_release", false);  // journals before it: by index
    t.head_on_priority = k.value("head_on_priority", false);        // journals before it: first come
    t.head_on_give_way = k.value("head_on_give_way", false);        // journals before it: no give-way
    const std::string execution = k.value("execution", std::string("times"));  // journals before it: times
    const auto parsed_execution = engine::ParsePlanExecution(execution);
    if (!parsed_execution) return Corrupt("run setup", "unknown execution " + execution);
    t.execution = *parsed_execution;
    const std::string head_on = k.at("head_on").get<std::string>();
    bool known = false;
    for (auto p : {engine::HeadOnPolicy::kChooseFaster, engine::HeadOnPolicy::kAlwaysWait,
                   engine::HeadOnPolicy::kAlwaysReplan}) {
      if (head_on == HeadOnName(p)) t.head_on = p, known = true;
    }
    if (!known) return Corrupt("run setup", "unknown head-on policy " + head_on);
    s.route_cache_bytes = j.at("route_cache_bytes").get<std::size_t>();
    s.route_table = j.value("route_table", std::string("floyd"));  // journals before it: floyd
    if (!engine::ParseRouteTableMethod(s.route_table).ok()) return Corrupt("run setup", "unknown route table " + s.route_table);
    s.time_scale = j.at("time_scale").get<double>();
    return s;
  });
}

Result<std::string> EncodeCoreInput(const CoreInput& in) {
  return Guard<std::string>("journal entry", false, [&]() -> Result<std::string> {
    json j = json::object();
    if (!in.robot_id.empty()) j["r"] = in.robot_id;
    if (!in.order_id.empty()) j["o"] = in.order_id;
    if (!in.reason.empty()) j["why"] = in.reason;
    if (in.order) {
      auto o = OrderJson(*in.order);
      if (!o.ok()) return o.error();
      j["order"] = *o;
    }
    if (!in.robots.empty()) j["robots"] = in.robots;
    if (in.robot) {
      auto r = RobotJson(*in.robot);
      if (!r.ok()) return r.error();
      j["robot"] = *r;
    }
    if (in.plan) {
      const engine::Assignment& a = *in.plan;
      j["plan"] = {{"robot", a.robot_id}, {"id", a.plan_id}, {"orders", a.order_ids},
                   {"released", a.released_up_to}, {"updated", a.updated_time},
                   {"waypoints", Embedded(EncodeWaypoints(a.plan.waypoints))}};
    }
    if (in.place) j["place"] = true;
    if (in.pose) j["p"] = PoseJson(*in.pose);
    if (in.arc_id) j["a"] = *in.arc_id;
    if (in.state) j["s"] = engine::RobotStateName(*in.state);
    if (in.battery) j["b"] = Num(*in.battery);
    if (in.sequence) j["n"] = in.sequence;
    if (in.kind == CoreInput::Kind::kPlanTask) j["task"] = {in.task.order_id, in.task.dropped};
    if (in.ref) j["ref"] = in.ref;
    if (in.change) j["change"] = in.change;
    if (in.max) j["max"] = in.max;
    if (in.cancelled) j["cancelled"] = true;
    if (in.marks != engine::OperatorMarks{}) j["marks"] = json::parse(EncodeMarks(in.marks));
    if (in.command) {
      j["cmd"] = {engine::RobotCommandName(in.command->kind), in.command->robot, in.command->by, in.command->to};
    }
    return j.dump();
  });
}

Result<CoreInput> DecodeCoreInput(CoreInput::Kind kind, double time, const std::string& text) {
  return Guard<CoreInput>("journal entry", true, [&]() -> Result<CoreInput> {
    const json j = json::parse(text);
    if (!j.is_object()) return Corrupt("journal entry", "not an object");
    CoreInput in;
    in.kind = kind;
    in.time = time;
    in.robot_id = j.value("r", "");
    in.order_id = j.value("o", "");
    in.reason = j.value("why", "");
    if (j.contains("order")) {
      auto o = OrderOf(j.at("order"));
      if (!o.ok()) return o.error();
      in.order = std::move(*o);
    }
    if (j.contains("robots")) in.robots = j.at("robots").get<std::vector<std::string>>();
    if (j.contains("robot")) {
      auto r = RobotOf(j.at("robot"));
      if (!r.ok()) return r.error();
      in.robot = std::move(*r);
    }
    if (j.contains("plan")) {
      const json& p = j.at("plan");
      engine::Assignment a;
      a.robot_id = p.at("robot").get<std::string>();
      a.plan_id = p.at("id").get<std::uint64_t>();
      a.order_ids = p.at("orders").get<std::vector<std::string>>();
      a.released_up_to = p.at("released").get<std::int64_t>();
      a.updated_time = p.at("updated").get<double>();
      auto waypoints = DecodeWaypoints(p.at("waypoints").dump());
      if (!waypoints.ok()) return waypoints.error();
      a.plan.robot_id = a.robot_id;
      a.plan.waypoints = std::move(*waypoints);
      in.plan = std::move(a);
    }
    in.place = j.value("place", false);
    if (j.contains("p")) in.pose = PoseOf(j.at("p"));
    if (j.contains("a")) in.arc_id = j.at("a").get<int>();
    if (j.contains("s")) {
      auto s = engine::ParseRobotState(j.at("s").get<std::string>());
      if (!s) return Corrupt("journal entry", "unknown robot state");
      in.state = *s;
    }
    if (j.contains("b")) in.battery = NumOf(j.at("b"));
    in.sequence = j.value("n", std::uint64_t{0});
    if (j.contains("task")) {
      in.task.order_id = j.at("task").at(0).get<std::string>();
      in.task.dropped = j.at("task").at(1).get<bool>();
    }
    in.ref = j.value("ref", std::uint64_t{0});
    in.change = j.value("change", std::uint64_t{0});
    in.max = j.value("max", std::size_t{0});
    in.cancelled = j.value("cancelled", false);
    if (j.contains("marks")) {
      auto marks = DecodeMarks(j.at("marks").dump());
      if (!marks.ok()) return marks.error();
      in.marks = std::move(*marks);
    }
    if (j.contains("cmd")) {
      const json& c = j.at("cmd");
      auto command = engine::ParseRobotCommand(c.at(0).get<std::string>());
      if (!command) return Corrupt("journal entry", "unknown robot command");
      in.command = engine::OperatorCommand{*command, c.at(1).get<std::string>(), c.at(2).get<std::string>(),
                                           c.at(3).get<engine::PointId>()};
    } else if (kind == CoreInput::Kind::kPlanCommand) {  // a journal's "pause" entry before "plan_command"
      in.command = engine::OperatorCommand{
          j.value("paused", false) ? engine::RobotCommandKind::kPause : engine::RobotCommandKind::kResume,
          in.robot_id, in.reason, engine::kNoPoint};
    }
    return in;
  });
}

}  // namespace dispatch::storage
