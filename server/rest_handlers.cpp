#include "server/rest_handlers.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <limits>
#include <set>
#include <string>

#include "engine/io/map_json.h"
#include "server/dispatcher.h"
#include "server/json_convert.h"
#include "server/metrics.h"

namespace dispatch::server {
namespace {

using nlohmann::json;

int HttpStatus(StatusCode code) {
  switch (code) {
    case StatusCode::kOk: return 200;
    case StatusCode::kInvalidArgument: return 400;
    case StatusCode::kNotFound: return 404;
    case StatusCode::kAlreadyExists: return 409;
    case StatusCode::kFailedPrecondition: return 409;
    case StatusCode::kUnavailable: return 503;
    case StatusCode::kInternal: return 500;
  }
  return 500;
}

// Messages echo client input (a path segment, a query value) that may be any bytes, and
// JSON text must be UTF-8 (dump() throws otherwise): invalid bytes become U+FFFD.
std::string Utf8(const std::string& text) {
  return json::parse(json(text).dump(-1, ' ', false, json::error_handler_t::replace)).get<std::string>();
}

RestReply Error(int status, const std::string& message) { return {status, {{"error", Utf8(message)}}}; }
RestReply Error(const ServiceStatus& s) { return Error(HttpStatus(s.code), s.message); }

engine::Result<engine::StopSpec> StopOf(const json& j, const std::string& what) {
  if (j.is_string()) return engine::StopSpec(j.get<std::string>());
  if (j.is_object() && j.contains("x") && j.contains("y") && j["x"].is_number() && j["y"].is_number()) {
    return engine::StopSpec(Eigen::Vector2d(j["x"].get<double>(), j["y"].get<double>()));
  }
  return engine::InvalidArgument(what + " must be a point name or {\"x\": .., \"y\": ..}");
}

// A present field of the wrong type, named (nlohmann's own message does not name it).
engine::Error WrongType(const std::string& field, const std::string& want, const json& got) {
  return engine::InvalidArgument(field + " must be " + want + ", got " + (got.is_number() ? got.dump() : got.type_name()));
}

engine::Result<engine::OrderRequest> RequestOf(const std::string& body) {
  json j;
  try {
    j = json::parse(body);
  } catch (const json::exception& e) {
    return engine::InvalidArgument(std::string("body is not JSON: ") + e.what());
  }
  if (!j.is_object()) return engine::InvalidArgument("body must be a JSON object");
  // A misspelt field would otherwise be dropped silently (e.g. "relase_time": the order would
  // start at once).
  static const std::set<std::string> kFields = {"client_order_id", "client_id", "priority", "picks",
                                                "drop", "formation", "work_time", "release_time"};
  for (const auto& [key, value] : j.items()) {
    if (!kFields.count(key)) {
      return engine::InvalidArgument("unknown field '" + key + "' (known: client_order_id, priority, picks, drop, "
                                     "formation, work_time, release_time)");
    }
  }
  engine::OrderRequest r;
  const char* id_key = j.contains("client_order_id") ? "client_order_id" : "client_id";
  if (!j.contains(id_key) || !j[id_key].is_string()) {
    return engine::InvalidArgument("client_order_id (string) is required");
  }
  r.client_id = j[id_key].get<std::string>();
  if (j.contains("priority")) {
    const json& p = j["priority"];
    // int32 as in SubmitOrderRequest; get<int>() would wrap 2^32 + 1 to 1 and cut 1.5 to 1.
    const bool fits = p.is_number_unsigned() ? p.get<std::uint64_t>() <= std::numeric_limits<std::int32_t>::max()
                      : p.is_number_integer() ? p.get<std::int64_t>() >= std::numeric_limits<std::int32_t>::min() &&
                                                    p.get<std::int64_t>() <= std::numeric_limits<std::int32_t>::max()
                                              : false;
    if (!fits) return WrongType("priority", "an integer in [-2^31, 2^31 - 1]", p);
    r.priority = p.get<int>();
  }
  if (!j.contains("picks") || !j["picks"].is_array()) {
    return engine::InvalidArgument("picks (array of stops) is required");
  }
  int k = 0;
  for (const auto& p : j["picks"]) {
    auto stop = StopOf(p, "pick " + std::to_string(++k));
    if (!stop.ok()) return stop.error();
    r.picks.push_back(*stop);
  }
  if (!j.contains("drop")) return engine::InvalidArgument("drop is required");
  auto drop = StopOf(j["drop"], "drop");
  if (!drop.ok()) return drop.error();
  r.drop = *drop;
  if (j.contains("formation")) {
    if (!j["formation"].is_boolean()) return WrongType("formation", "true or false", j["formation"]);
    r.formation = j["formation"].get<bool>();
  }
  if (j.contains("work_time")) {
    if (!j["work_time"].is_number()) return WrongType("work_time", "a number of seconds", j["work_time"]);
    r.work_time = j["work_time"].get<double>();
  }
  if (j.contains("release_time") && !j["release_time"].is_null()) {
    const json& t = j["release_time"];
    if (!t.is_number() || !std::isfinite(t.get<double>())) {
      return WrongType("release_time", "a finite number of seconds or null", t);
    }
    r.release_time = t.get<double>();
  }
  return r;
}

}  // namespace

RestHandlers::RestHandlers(Dispatcher& dispatcher, ServiceMetrics* metrics)
    : dispatcher_(dispatcher),
      metrics_(metrics),
      map_json_(std::make_shared<const std::string>(engine::WriteMapJson(dispatcher.map()))) {}

RestReply RestHandlers::Map() const { return RestReply::Text("application/json", *map_json_); }

RestReply RestHandlers::Zones() const {
  auto snap = dispatcher_.snapshot();
  const auto& zones = dispatcher_.map().zones();
  json out = json::array();
  for (std::size_t z = 0; z < zones.size(); ++z) {
    json polygon = json::array();
    for (const auto& v : zones[z].polygon) polygon.push_back({v.x(), v.y()});
    const ZoneView* live = z < snap->zones.size() ? &snap->zones[z] : nullptr;
    out.push_back({{"id", zones[z].name},
                   {"polygon", polygon},
                   {"area", zones[z].area},
                   {"robots", live ? live->robots.size() : 0},
                   {"density", live ? live->density : 0.0},
                   {"robot_ids", live ? json(live->robots) : json::array()}});
  }
  return {200, {{"time", snap->time}, {"zones", out}}};
}

RestReply RestHandlers::Intersections(const std::optional<std::string>& active) const {
  bool only_active = false;
  if (active) {
    if (*active == "1" || *active == "true") {
      only_active = true;
    } else if (*active != "0" && *active != "false") {
      return Error(400, "active must be 1, true, 0 or false");
    }
  }
  auto snap = dispatcher_.snapshot();
  const engine::WarehouseMap& map = dispatcher_.map();
  auto names = [&map](const std::vector<engine::PointId>& points) {
    json out = json::array();
    for (engine::PointId p : points) out.push_back(map.point(p).name);
    return out;
  };
  json out = json::array();
  for (std::size_t i = 0; i < map.intersections().size(); ++i) {
    const auto& x = map.intersections()[i];
    const IntersectionView* live = i < snap->intersections.size() ? &snap->intersections[i] : nullptr;
    if (only_active && (!live || (live->holders.empty() && live->waiting.empty()))) continue;
    out.push_back({{"id", x.name},
                   {"inner", names(x.inner)},
                   {"approach", names(x.approach)},
                   {"holders", live ? json(live->holders) : json::array()},
                   {"waiting", live ? json(live->waiting) : json::array()}});
  }
  return {200, {{"time", snap->time}, {"control", snap->traffic.enabled}, {"intersections", out}}};
}

RestReply RestHandlers::Metrics() const {
  if (!metrics_) return Error(404, "metrics are not enabled");
  return RestReply::Text("text/plain; version=0.0.4; charset=utf-8", metrics_->Render(*dispatcher_.snapshot()));
}

RestReply RestHandlers::Health() const { return {200, {{"status", "ok"}}}; }

RestReply RestHandlers::Ready() const {
  auto snap = dispatcher_.snapshot();
  if (!snap) return Error(503, "dispatcher not ready");
  return {200, {{"ready", true}, {"snapshot", snap->version}}};
}

RestReply RestHandlers::Status() const {
  auto snap = dispatcher_.snapshot();
  json orders = json::object();
  for (const char* s : {"accepted", "assigned", "in_progress", "completed", "cancelled", "failed"}) {
    orders[s] = 0;
  }
  for (const auto& o : snap->orders) orders[engine::OrderStateName(o->record.order.state)] = orders[engine::OrderStateName(o->record.order.state)].get<int>() + 1;
  int connected = 0;
  for (const auto& [id, r] : snap->robots) connected += r.connected ? 1 : 0;
  const TrafficView& t = snap->traffic;
  json traffic = {{"control", t.enabled},
                  {"grants", t.grants},
                  {"holds", t.holds},
                  {"replans", t.replans},
                  {"deadlocks_resolved", t.deadlocks_resolved},
                  {"head_on_conflicts", t.head_on_conflicts},
                  {"nudges", t.nudges},
                  {"implausible_reports", t.implausible_reports},
                  {"awaiting_reconnect", t.awaiting_reconnect},
                  {"min_robot_distance", nullptr}};
  if (t.min_distance >= 0) {
    traffic["min_robot_distance"] = {{"distance", t.min_distance},
                                     {"robots", {t.min_pair_a, t.min_pair_b}},
                                     {"time", t.min_time}};
  }
  return {200,
          {{"map", snap->map_name},
           {"map_version", snap->map_version},
           {"strategy", snap->strategy},
           {"time", snap->time},
           {"time_scale", snap->time_scale},
           {"snapshot", snap->version},
           {"orders", orders},
           {"robots", {{"total", snap->robots.size()}, {"connected", connected}}},
           {"traffic", traffic}}};
}

RestReply RestHandlers::Traffic() {
  using Lines = std::vector<std::pair<std::string, std::string>>;
  Lines lines = dispatcher_.Call<Lines>([this](std::function<void(Lines)> done) {
    done(dispatcher_.TrafficLines());
  });
  json robots = json::object();
  for (const auto& [id, line] : lines) robots[id] = line;
  return {200, {{"robots", robots}}};
}

RestReply RestHandlers::Robots() const {
  auto snap = dispatcher_.snapshot();
  json robots = json::array();
  for (const auto& [id, r] : snap->robots) robots.push_back(RobotToJson(r, dispatcher_.map()));
  return {200, {{"robots", robots}}};
}

RestReply RestHandlers::Robot(const std::string& id) const {
  auto snap = dispatcher_.snapshot();
  auto it = snap->robots.find(id);
  if (it == snap->robots.end()) return Error(404, "no robot with id '" + id + "'");
  return {200, RobotToJson(it->second, dispatcher_.map())};
}

RestReply RestHandlers::Orders(const std::optional<std::string>& state,
                               const std::optional<std::string>& finished) const {
  std::optional<engine::OrderState> filter;
  if (state) {
    filter = engine::ParseOrderState(*state);
    if (!filter) {
      return Error(400, "unknown state '" + *state +
                            "' (accepted, assigned, in_progress, completed, cancelled, failed)");
    }
  }
  std::size_t keep = kListedFinished;
  if (finished) {
    const std::string& f = *finished;
    const bool digits = !f.empty() && f.size() <= 4 && std::all_of(f.begin(), f.end(), [](char c) {
      return std::isdigit(static_cast<unsigned char>(c));
    });
    if (!digits || std::stoul(f) > kMaxListedFinished) {
      return Error(400, "finished must be a whole number from 0 to " + std::to_string(kMaxListedFinished));
    }
    keep = std::stoul(f);
  }
  auto snap = dispatcher_.snapshot();
  std::vector<std::size_t> open, done;  // indexes into the snapshot's orders
  for (std::size_t i = 0; i < snap->orders.size(); ++i) {
    const auto& o = snap->orders[i];
    if (filter && o->record.order.state != *filter) continue;
    (engine::IsTerminal(o->record.order.state) ? done : open).push_back(i);
  }
  const std::size_t finished_total = done.size();
  if (done.size() > keep) {  // the newest finished: by finished time, then submission
    auto newer = [&](std::size_t a, std::size_t b) {
      const double ta = snap->orders[a]->finished_time.value_or(0.0), tb = snap->orders[b]->finished_time.value_or(0.0);
      return ta != tb ? ta > tb : a > b;
    };
    std::nth_element(done.begin(), done.begin() + static_cast<std::ptrdiff_t>(keep), done.end(), newer);
    done.resize(keep);
  }
  std::vector<std::size_t> listed = open;
  listed.insert(listed.end(), done.begin(), done.end());
  std::sort(listed.begin(), listed.end());
  json orders = json::array();
  for (const std::size_t i : listed) orders.push_back(OrderToJson(*snap->orders[i], dispatcher_.map(), false));
  return {200, {{"orders", orders}, {"finished_total", finished_total}}};
}

RestReply RestHandlers::Order(const std::string& id) {
  auto snap = dispatcher_.snapshot();
  auto order = snap->FindOrder(id);
  if (!order) order = snap->FindClientOrder(id);
  if (!order) return Error(404, "no order with id or client id '" + id + "'");
  json j = OrderToJson(*order, dispatcher_.map(), true);
  const std::string order_id = order->record.order.id;
  OrderRoutes routes = dispatcher_.Call<OrderRoutes>([this, order_id](std::function<void(OrderRoutes)> done) {
    done(dispatcher_.RoutesOf(order_id));
  });
  json by_robot = json::object();
  for (const auto& [robot, waypoints] : routes) {
    json list = json::array();
    for (const auto& w : waypoints) {
      list.push_back({{"seq", w.seq}, {"x", w.xy.x()}, {"y", w.xy.y()},
                      {"action", engine::WaypointActionName(w.action)}, {"released", w.released}});
    }
    by_robot[robot] = list;
  }
  j["routes"] = by_robot;
  return {200, j};
}

RestReply RestHandlers::SubmitOrder(const std::string& body) {
  auto request = RequestOf(body);
  if (!request.ok()) return Error(FromEngineError(request.error()));
  SubmitReply reply = dispatcher_.Call<SubmitReply>(
      [this, r = std::move(request).value()](std::function<void(SubmitReply)> done) mutable {
        dispatcher_.SubmitOrder(std::move(r), std::move(done));
      });
  if (!reply.status.ok()) return Error(reply.status);
  json j = OrderToJson(*reply.order, dispatcher_.map(), false);
  j["created"] = reply.created;
  return {reply.created ? 201 : 200, j};
}

RestReply RestHandlers::CancelOrder(const std::string& id, const std::string& reason) {
  OrderReply reply = dispatcher_.Call<OrderReply>([this, id, reason](std::function<void(OrderReply)> done) {
    dispatcher_.CancelOrder(id, reason, std::move(done));
  });
  if (!reply.status.ok()) return Error(reply.status);
  return {200, OrderToJson(*reply.order, dispatcher_.map(), false)};
}

}  // namespace dispatch::server
