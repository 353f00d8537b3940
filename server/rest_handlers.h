// RestHandlers: the REST API's logic (SPEC §4 "REST"), answering with an HTTP status and a
// JSON body; rest_api.cpp only routes cpp-httplib requests here. This header is free of
// Eigen and engine headers so that httplib.h (whose <resolv.h> defines `_res`) never meets
// Eigen in one translation unit (STYLE.md). Reads use the dispatcher's snapshot; writes wait
// for the dispatcher loop's reply. Thread-safe.
#pragma once

#include <nlohmann/json.hpp>

#include <optional>
#include <string>

namespace dispatch::server {

class Dispatcher;

struct RestReply {
  int status = 200;
  nlohmann::json body;
};

class RestHandlers {
 public:
  explicit RestHandlers(Dispatcher& dispatcher) : dispatcher_(dispatcher) {}

  RestReply Health() const;
  RestReply Ready() const;
  RestReply Status() const;
  RestReply Robots() const;
  RestReply Robot(const std::string& id) const;
  // state: a lower-case order state name, or nullopt for all.
  RestReply Orders(const std::optional<std::string>& state) const;
  // GET /api/v1/traffic: every robot's traffic state (where, route, what it waits on).
  RestReply Traffic();
  RestReply Order(const std::string& id) const;
  // body: {"client_order_id": "...", "picks": ["P1-1-1" | {"x":..,"y":..}, ...],
  //        "drop": "D1" | {"x":..,"y":..}, "priority": 0, "formation": false,
  //        "work_time": 5.0, "release_time": 0.0}
  RestReply SubmitOrder(const std::string& body);
  RestReply CancelOrder(const std::string& id, const std::string& reason);

 private:
  Dispatcher& dispatcher_;
};

}  // namespace dispatch::server
