#include "clients/order_file.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <optional>
#include <utility>

#include "formats/json_keys.h"
#include "formats/task_table_text.h"

namespace dispatch::clients {
namespace {

using nlohmann::json;

// Sets `why` and returns nothing: a helper's failure, its message for the operator.
std::nullopt_t Fail(std::string& why, std::string message) {
  why = std::move(message);
  return std::nullopt;
}

v1::StopSpec ToStop(const formats::Xy& xy) {
  v1::StopSpec out;
  out.mutable_position()->set_x(xy[0]);
  out.mutable_position()->set_y(xy[1]);
  return out;
}

std::optional<v1::StopSpec> JsonStop(const json& j, const std::string& where, std::string& why) {
  v1::StopSpec out;
  if (j.is_string()) {
    if (j.get<std::string>().empty()) return Fail(why, where + ": empty point name");
    out.set_point_name(j.get<std::string>());
    return out;
  }
  if (!j.is_object()) return Fail(why, where + ": a stop is a point name or {\"x\", \"y\"}");
  if (j.contains("heading")) {
    if (!j["heading"].is_number() || !std::isfinite(j["heading"].get<double>())) {
      return Fail(why, where + ".heading: must be a finite number (radians)");
    }
    out.set_heading(j["heading"].get<double>());
  }
  if (j.contains("point")) {
    if (!j["point"].is_string() || j["point"].get<std::string>().empty()) {
      return Fail(why, where + ".point: must be a non-empty string");
    }
    out.set_point_name(j["point"].get<std::string>());
    return out;
  }
  for (const char* key : {"x", "y"}) {
    if (!j.contains(key) || !j[key].is_number() || !std::isfinite(j[key].get<double>())) {
      return Fail(why, where + "." + key + ": missing or not a finite number");
    }
  }
  out.mutable_position()->set_x(j["x"].get<double>());
  out.mutable_position()->set_y(j["y"].get<double>());
  return out;
}

std::optional<v1::SubmitOrderRequest> JsonOrder(const json& j, std::size_t index, const std::string& prefix,
                                                std::string& why) {
  const std::string where = "order " + std::to_string(index + 1);
  if (!j.is_object()) return Fail(why, where + ": must be a JSON object");
  static const char* const kKnown[] = {"client_order_id", "priority", "formation", "work_time",
                                       "release_time", "picks", "drop"};
  for (const auto& [key, value] : j.items()) {
    bool known = false;
    for (const char* k : kKnown) known = known || key == k;
    if (!known) return Fail(why, where + ": unknown field '" + key + "'");
  }
  v1::SubmitOrderRequest r;
  if (j.contains("client_order_id")) {
    if (!j["client_order_id"].is_string() || j["client_order_id"].get<std::string>().empty()) {
      return Fail(why, where + ".client_order_id: must be a non-empty string");
    }
    r.set_client_order_id(j["client_order_id"].get<std::string>());
  } else {
    r.set_client_order_id(prefix + std::to_string(index + 1));
  }
  if (j.contains("priority")) {
    if (!j["priority"].is_number_integer()) return Fail(why, where + ".priority: must be an integer");
    r.set_priority(j["priority"].get<int>());
  }
  if (j.contains("formation")) {
    if (!j["formation"].is_boolean()) return Fail(why, where + ".formation: must be true or false");
    r.set_formation(j["formation"].get<bool>());
  }
  for (const char* key : {"work_time", "release_time"}) {
    if (!j.contains(key)) continue;
    if (!j[key].is_number() || !std::isfinite(j[key].get<double>()) || j[key].get<double>() < 0) {
      return Fail(why, where + "." + key + ": must be a finite number >= 0");
    }
    if (std::string(key) == "work_time") r.set_work_time(j[key].get<double>());
    else r.set_release_time(j[key].get<double>());
  }
  if (!j.contains("picks") || !j["picks"].is_array() || j["picks"].empty()) {
    return Fail(why, where + ".picks: must be a non-empty array of stops");
  }
  for (std::size_t k = 0; k < j["picks"].size(); ++k) {
    auto stop = JsonStop(j["picks"][k], where + ".picks[" + std::to_string(k) + "]", why);
    if (!stop) return std::nullopt;
    *r.add_picks() = std::move(*stop);
  }
  if (!j.contains("drop")) return Fail(why, where + ".drop: missing");
  auto drop = JsonStop(j["drop"], where + ".drop", why);
  if (!drop) return std::nullopt;
  *r.mutable_drop() = std::move(*drop);
  return r;
}

}  // namespace

OrderFile ParseOrderText(std::string_view text, bool is_json, const std::string& prefix) {
  OrderFile out;
  auto fail = [&out](std::string why) {
    out.orders.clear();
    out.error = std::move(why);
    return out;
  };
  if (!is_json) {
    formats::TaskTableText table = formats::ParseTaskTableText(text);
    if (!table.ok()) return fail(table.error);
    for (const formats::TaskRow& row : table.rows) {
      v1::SubmitOrderRequest r;
      r.set_client_order_id(prefix + row.task);
      r.set_formation(row.formation);
      for (const formats::Xy& p : row.picks) *r.add_picks() = ToStop(p);
      *r.mutable_drop() = ToStop(row.drop);
      if (row.release) r.set_release_time(*row.release);
      out.orders.push_back(std::move(r));
    }
    return out;
  }
  json doc;
  std::optional<std::string> key;
  try {
    doc = formats::ParseNotingDuplicateKey(text, &key);
  } catch (const json::exception& e) {  // a syntax error, or a number too large (fuzz_order_file)
    return fail(std::string("bad JSON: ") + e.what());
  }
  if (key) return fail("the key '" + *key + "' appears twice in one object");
  if (doc.is_object() && doc.contains("orders")) doc = doc["orders"];
  if (!doc.is_array()) doc = json::array({doc});
  if (doc.empty()) return fail("no orders in the file");
  for (std::size_t i = 0; i < doc.size(); ++i) {
    std::string why;
    auto r = JsonOrder(doc[i], i, prefix, why);
    if (!r) return fail(why);
    out.orders.push_back(std::move(*r));
  }
  return out;
}

OrderFile LoadOrderFile(const std::string& path, const std::string& prefix) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return {{}, "cannot read " + path};
  std::ostringstream text;
  text << in.rdbuf();
  const std::filesystem::path p(path);
  const bool is_json = p.extension() == ".json";
  OrderFile orders = ParseOrderText(text.str(), is_json, prefix.empty() ? p.stem().string() + "-" : prefix);
  if (!orders.ok()) orders.error = path + ": " + orders.error;
  return orders;
}

v1::StopSpec ParseStopArgument(const std::string& text) {
  std::string t = text;
  for (char& c : t) c = c == ',' ? ' ' : c;
  std::istringstream in(t);
  double x = 0, y = 0;
  std::string rest;
  if (in >> x >> y && !(in >> rest)) {
    v1::StopSpec s;
    s.mutable_position()->set_x(x);
    s.mutable_position()->set_y(y);
    return s;
  }
  v1::StopSpec s;
  s.set_point_name(text);
  return s;
}

}  // namespace dispatch::clients
