// RestServer: cpp-httplib HTTP server routing to RestHandlers (GET /healthz, /readyz,
// /api/v1/status, /api/v1/robots[/{id}], /api/v1/orders[?state=], /api/v1/orders/{id},
// /api/v1/map, /api/v1/zones, /api/v1/intersections, /api/v1/traffic, /metrics;
// POST /api/v1/orders, /api/v1/robots/{id}/pause, /api/v1/robots/{id}/resume; DELETE
// /api/v1/orders/{id}[?reason=]) and serving the web map at `/`
// (server/web/). Errors are 4xx/5xx with {"error": "..."}. Runs its own listener thread and
// httplib's worker pool.
//
// Security (issue 18): HTTPS when given a certificate and key; with an Authenticator that is
// enabled every /api/v1 endpoint needs `Authorization: Bearer <token>` of a role that may do
// it (401 / 403 otherwise, server/auth.h), /metrics too unless metrics_open; /healthz,
// /readyz and the web map's own files stay open. POST bodies must say Content-Type
// application/json (415 otherwise: a cross-origin form or text/plain POST cannot create
// orders).
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

class Authenticator;

struct RestSecurity {
  std::string tls_cert;  // PEM files; both empty: plain HTTP
  std::string tls_key;
  const Authenticator* auth = nullptr;  // null: no authentication (must outlive the server)
  bool metrics_open = false;
};

class RestServer {
 public:
  // web_root: serve the web map from this folder ("" = the built-in copy).
  RestServer(RestHandlers handlers, const std::string& web_root, const RestSecurity& security = {});
  // False when the TLS certificate or key could not be loaded.
  bool valid() const;
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
