// RestHandlers: the REST API's logic (SPEC §4 "REST"), answering with an HTTP status and a
// JSON body; rest_api.cpp only routes cpp-httplib requests here. This header is free of
// Eigen and engine headers so that httplib.h (whose <resolv.h> defines `_res`) never meets
// Eigen in one translation unit (STYLE.md). Reads use the dispatcher's snapshot; writes wait
// for the dispatcher loop's reply. Thread-safe.
#pragma once

#include <nlohmann/json.hpp>

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <utility>

namespace dispatch::server {

class Dispatcher;
class ServiceMetrics;

// Finished orders GET /api/v1/orders lists by default and at most (the newest).
inline constexpr std::size_t kListedFinished = 100;
inline constexpr std::size_t kMaxListedFinished = 1000;

// A JSON body, or (content_type set) `text` as it is.
struct RestReply {
  RestReply(int status, nlohmann::json body) : status(status), body(std::move(body)) {}
  static RestReply Text(std::string content_type, std::string text) {
    RestReply r(200, nullptr);
    r.content_type = std::move(content_type);
    r.text = std::move(text);
    return r;
  }
  int status = 200;
  nlohmann::json body;
  std::string content_type;
  std::string text;
};

class RestHandlers {
 public:
  // `metrics` may be null (GET /metrics then answers 404).
  RestHandlers(Dispatcher& dispatcher, ServiceMetrics* metrics);

  RestReply Health() const;
  RestReply Ready() const;
  RestReply Status() const;
  RestReply Robots() const;
  RestReply Robot(const std::string& id) const;
  // state: a lower-case order state name, or nullopt for all.
  // Every open order and the newest `finished` (default kListedFinished, at most
  // kMaxListedFinished) finished ones, in submission order, with finished_total: a list that
  // held every order ever stored grew each HTTP thread's heap with the whole history (issue 15
  // §3b: 140 kB per order with the web map polling).
  RestReply Orders(const std::optional<std::string>& state, const std::optional<std::string>& finished) const;
  // GET /api/v1/traffic: every robot's traffic state (where, route, what it waits on).
  RestReply Traffic();
  // With the allocation explanation and "routes": each robot's waypoints of it not reached.
  RestReply Order(const std::string& id);
  // GET /api/v1/map: the map in the JSON map format (engine/io/map_format.md).
  RestReply Map() const;
  // GET /api/v1/zones: each zone's polygon, area and live density.
  RestReply Zones() const;
  // GET /api/v1/intersections: each intersection's regions, grant holders and waiters;
  // ?active=1 (or true) only those with a holder or a waiter (large floors have thousands).
  RestReply Intersections(const std::optional<std::string>& active = std::nullopt) const;
  // GET /metrics: Prometheus text format.
  RestReply Metrics() const;
  // body: {"client_order_id": "...", "picks": ["P1-1-1" | {"x":..,"y":..}, ...],
  //        "drop": "D1" | {"x":..,"y":..}, "priority": 0, "formation": false,
  //        "work_time": 5.0, "release_time": 0.0}
  RestReply SubmitOrder(const std::string& body);
  RestReply CancelOrder(const std::string& id, const std::string& reason);

 private:
  Dispatcher& dispatcher_;
  ServiceMetrics* metrics_;
  std::shared_ptr<const std::string> map_json_;  // built once
};

}  // namespace dispatch::server
