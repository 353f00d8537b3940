// RestServer: cpp-httplib HTTP server routing to RestHandlers (GET /healthz, /readyz,
// /api/v1/status, /api/v1/robots[/{id}], /api/v1/orders[?state=], /api/v1/orders/{id};
// POST /api/v1/orders; DELETE /api/v1/orders/{id}[?reason=]). Errors are 4xx/5xx with
// {"error": "..."}. Runs its own listener thread and httplib's worker pool.
// Thread-safe: Start once, Stop from any thread.
#pragma once

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
  explicit RestServer(RestHandlers handlers);
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
};

}  // namespace dispatch::server
