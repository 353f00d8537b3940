// RestServer: cpp-httplib HTTP server routing to RestHandlers (GET /healthz, /readyz,
// /api/v1/status, /api/v1/robots[/{id}], /api/v1/orders[?state=], /api/v1/orders/{id},
// /api/v1/map, /api/v1/zones, /api/v1/intersections, /api/v1/traffic, /metrics;
// POST /api/v1/orders; DELETE /api/v1/orders/{id}[?reason=]) and serving the web map at `/`
// (server/web/). Errors are 4xx/5xx with {"error": "..."}. Runs its own listener thread and
// httplib's worker pool.
// Thread-safe: Start once, Stop from any thread.
#pragma once

#include <atomic>
#include <memory>
#include <string>
#include <thread>

#include "server/rest_handlers.h"

namespace httplib {
class Server;
}

namespace dispatch::server {

class RestServer {
 public:
  // web_root: serve the web map from this folder ("" = the built-in copy).
  RestServer(RestHandlers handlers, const std::string& web_root);
  ~RestServer();
  RestServer(const RestServer&) = delete;
  RestServer& operator=(const RestServer&) = delete;

  // Binds `bind`:`port` (0 = any free port) and starts serving. Returns the bound port, or
  // -1 if binding failed.
  int Start(const std::string& bind, int port);
  void Stop();

 private:
  RestHandlers handlers_;
  std::unique_ptr<httplib::Server> http_;
  std::thread thread_;
  std::atomic<bool> listening_{false};  // the listener thread is inside listen_after_bind
};

}  // namespace dispatch::server
