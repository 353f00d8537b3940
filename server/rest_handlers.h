// RestHandlers: the REST API's logic (SPEC §4 "REST"), answering with an HTTP status and a
// JSON body; rest_api.cpp only routes cpp-httplib requests here. This header is free of
// Eigen and engine headers so that httplib.h (whose <resolv.h> defines `_res`) never meets
// Eigen in one translation unit (STYLE.md). Every JSON body is a proto message's JSON mapping
// (issue 15 §2): REST and gRPC have one schema. Reads use the dispatcher's snapshot; writes wait
// for the dispatcher loop's reply. Thread-safe.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "engine/dispatch/robot_commands.h"
#include "server/auth.h"

namespace dispatch::server {

class Dispatcher;
class ServiceMetrics;
enum class StatusCode;

// The one mapping of service codes onto HTTP statuses (401, 403, 409, 503, ...).
int HttpStatus(StatusCode code);

// Finished orders GET /api/v1/orders lists by default and at most (the newest).
inline constexpr std::size_t kListedFinished = 100;
inline constexpr std::size_t kMaxListedFinished = 1000;

// An answer: a JSON body (the proto3 JSON mapping of an operator.proto / orders.proto
// message, see server/rest_views.h) or, for the map and the metrics, text of its own type.
struct RestReply {
  int status = 200;
  std::string text;
  std::string content_type = "application/json";
};

class RestHandlers {
 public:
  // `metrics` may be null (GET /metrics then answers 404). `store_health` (optional): why
  // the database cannot take writes now (nullopt: it can), for GET /readyz.
  RestHandlers(Dispatcher& dispatcher, ServiceMetrics* metrics,
               std::function<std::optional<std::string>()> store_health = {});

  RestReply Health() const;
  RestReply Ready() const;
  RestReply Status() const;
  RestReply Robots() const;
  RestReply Robot(const std::string& id) const;
  // POST /api/v1/robots/{id}/pause | /resume (issue 18 §4): the robot's RobotInfo afterwards.
  // POST /api/v1/robots/{id}/pause | resume | out-of-service | return-to-service | clear
  // (no body), /send (a SendRobotRequest's JSON, the robot id from the path): the RobotInfo after it.
  RestReply CommandRobot(engine::RobotCommandKind kind, const std::string& id, const std::string& actor);
  RestReply SendRobot(const std::string& id, const std::string& body, const std::string& actor);
  // state: an order state, lower case (in_progress) or as the enum (ORDER_STATE_IN_PROGRESS);
  // nullopt for all.
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
  // body: a SubmitOrderRequest, e.g. {"client_order_id": "...", "picks": [{"point_name":
  // "P1-1-1"} | {"position": {"x": .., "y": ..}}, ...], "drop": {...}, "priority": 0,
  // "formation": false, "work_time": 5.0, "release_time": 0.0}; answers a SubmitOrderResponse.
  // `actor`: who asks (the token's name; "" without tokens), journaled with the order's events.
  RestReply SubmitOrder(const std::string& body, const std::string& actor = "");
  RestReply CancelOrder(const std::string& id, const std::string& reason, const std::string& actor = "");

  // An ErrorReply body (also for httplib's own errors: 404, 413, ...).
  static std::string ErrorBody(const std::string& message);
  // GET /api/v1/session: the caller (a Session message).
  static RestReply Session(const Principal& who, bool tokens_required);

 private:
  RestReply Command(engine::RobotCommandKind kind, const std::string& id, const std::string& station,
                    const std::string& actor);
  Dispatcher& dispatcher_;
  ServiceMetrics* metrics_;
  std::function<std::optional<std::string>()> store_health_;
  std::shared_ptr<const std::string> map_json_;  // built once
};

}  // namespace dispatch::server
