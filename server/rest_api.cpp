// Only httplib and the Eigen-free rest_handlers.h here (see rest_handlers.h).
#include "server/rest_api.h"

#include <httplib.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "server/auth.h"
#include "server/service_status.h"
#include "server/web_assets.h"

namespace dispatch::server {
namespace {

// Request bodies beyond this get 413: the largest order (100 picks) is ~5 kB of JSON.
constexpr std::size_t kMaxBodyBytes = std::size_t{1} << 20;
// httplib serves a connection on one pool thread until it closes: a client that stalls
// mid-request holds its thread for the read timeout, an idle keep-alive connection (a browser
// polling the web map) for the keep-alive timeout. The default pool of 8 threads made 8 such
// clients stall everyone; 64 threads and short timeouts keep /healthz answering.
constexpr std::size_t kHttpThreads = 64;
constexpr time_t kReadTimeoutSeconds = 2;
constexpr time_t kKeepAliveSeconds = 2;

void Reply(httplib::Response& res, const RestReply& reply) {
  res.status = reply.status;
  res.set_content(reply.text, reply.content_type);
}

const char* ContentTypeOf(const std::filesystem::path& file) {
  const std::string ext = file.extension().string();
  if (ext == ".html") return "text/html";
  if (ext == ".js") return "text/javascript";
  if (ext == ".css") return "text/css";
  if (ext == ".svg") return "image/svg+xml";
  if (ext == ".png") return "image/png";
  if (ext == ".json") return "application/json";
  return "application/octet-stream";
}

// GET of a file below `root` (the web map from a folder, --web-root). The path is resolved
// (symbolic links, "..") and must stay inside the folder: a link inside pointing out of it is
// not followed (404), as nothing outside the folder is served (issue 18 §3).
void ServeWebRoot(httplib::Server& s, const std::string& web_root) {
  std::error_code ec;
  const std::filesystem::path root = std::filesystem::canonical(web_root, ec);
  s.Get(R"(/(.*))", [root](const httplib::Request& req, httplib::Response& res) {
    std::string rel = req.matches[1];
    if (rel.empty() || rel.back() == '/') rel += "index.html";
    std::error_code err;
    const std::filesystem::path file = std::filesystem::canonical(root / rel, err);
    const auto [in_root, in_file] = std::mismatch(root.begin(), root.end(), file.begin(), file.end());
    std::string body;
    if (err || root.empty() || in_root != root.end() || !std::filesystem::is_regular_file(file, err)) {
      Reply(res, {404, RestHandlers::ErrorBody("no such file in the web root: /" + req.matches[1].str())});
      return;
    }
    std::ifstream in(file, std::ios::binary);
    body.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    res.set_content(body, ContentTypeOf(file));
    res.set_header("Cache-Control", "no-cache");
  });
}

// The web map: the copy built into the binary (from a folder: ServeWebRoot, registered after
// the API's routes, which it would otherwise shadow).
void ServeWebMap(httplib::Server& s, const std::string& web_root) {
  if (!web_root.empty()) return;
  for (const WebAsset& asset : BuiltInWebAssets()) {
    auto serve = [&asset](const httplib::Request&, httplib::Response& res) {
      res.set_content(asset.body.data(), asset.body.size(), std::string(asset.content_type).c_str());
      res.set_header("Cache-Control", "no-cache");
    };
    s.Get(std::string(asset.path), serve);
    if (asset.path == "/index.html") s.Get("/", serve);
  }
}

std::unique_ptr<httplib::Server> MakeServer(const RestSecurity& security) {
  if (security.tls_cert.empty()) return std::make_unique<httplib::Server>();
  return std::make_unique<httplib::SSLServer>(security.tls_cert.c_str(), security.tls_key.c_str());
}

using Handler = std::function<void(const httplib::Request&, httplib::Response&)>;
// A handler that is told who calls (the token's name; "" without tokens).
using ActorHandler = std::function<void(const httplib::Request&, httplib::Response&, const std::string&)>;

// `handler` behind the authorization of `access` (none when auth is null or off).
Handler Guarded(const Authenticator* auth, Access access, ActorHandler handler) {
  if (!auth || !auth->enabled()) {
    return [handler = std::move(handler)](const httplib::Request& req, httplib::Response& res) {
      handler(req, res, "");
    };
  }
  return [auth, access, handler = std::move(handler)](const httplib::Request& req, httplib::Response& res) {
    const bool given = req.has_header("Authorization");
    const std::string value = given ? req.get_header_value("Authorization") : std::string();
    const Authenticator::Outcome outcome =
        auth->Authorize(given ? std::optional<std::string_view>(value) : std::nullopt, access);
    if (!outcome.status.ok()) {
      if (outcome.status.code == StatusCode::kUnauthenticated) res.set_header("WWW-Authenticate", "Bearer");
      Reply(res, {HttpStatus(outcome.status.code), RestHandlers::ErrorBody(outcome.status.message)});
      return;
    }
    handler(req, res, outcome.principal.name);
  };
}

Handler Guarded(const Authenticator* auth, Access access, Handler handler) {
  return Guarded(auth, access, ActorHandler([handler = std::move(handler)](const httplib::Request& req,
                                                                           httplib::Response& res,
                                                                           const std::string&) { handler(req, res); }));
}

// POST bodies are JSON: anything else (a form, text/plain, which browsers send cross-origin
// without asking) is refused with 415.
bool JsonBody(const httplib::Request& req, httplib::Response& res) {
  const std::string type = req.get_header_value("Content-Type");
  const std::string media = type.substr(0, type.find(';'));
  if (media == "application/json") return true;
  Reply(res, {415, RestHandlers::ErrorBody("the body must be JSON: send Content-Type: application/json (got '" +
                                           type.substr(0, 100) + "')")});
  return false;
}

}  // namespace

RestServer::RestServer(RestHandlers handlers, const std::string& web_root, const RestSecurity& security)
    : handlers_(handlers), http_(MakeServer(security)) {
  auto& h = handlers_;
  auto& s = *http_;
  const Authenticator* auth = security.auth;
  ServeWebMap(s, web_root);
  s.Get("/metrics", security.metrics_open
                        ? Handler([&h](const httplib::Request&, httplib::Response& res) { Reply(res, h.Metrics()); })
                        : Guarded(auth, Access::kMetrics,
                                  [&h](const httplib::Request&, httplib::Response& res) { Reply(res, h.Metrics()); }));
  s.Get("/api/v1/map", Guarded(auth, Access::kReadMap,
                               [&h](const httplib::Request&, httplib::Response& res) { Reply(res, h.Map()); }));
  s.Get("/api/v1/zones", Guarded(auth, Access::kReadFleet,
                                 [&h](const httplib::Request&, httplib::Response& res) { Reply(res, h.Zones()); }));
  s.Get("/api/v1/intersections",
        Guarded(auth, Access::kReadFleet, [&h](const httplib::Request& req, httplib::Response& res) {
          std::optional<std::string> active;
          if (req.has_param("active")) active = req.get_param_value("active");
          Reply(res, h.Intersections(active));
        }));
  s.Get("/healthz", [&h](const httplib::Request&, httplib::Response& res) { Reply(res, h.Health()); });
  s.Get("/readyz", [&h](const httplib::Request&, httplib::Response& res) { Reply(res, h.Ready()); });
  s.Get("/api/v1/status", Guarded(auth, Access::kReadFleet,
                                  [&h](const httplib::Request&, httplib::Response& res) { Reply(res, h.Status()); }));
  s.Get("/api/v1/robots", Guarded(auth, Access::kReadFleet,
                                  [&h](const httplib::Request&, httplib::Response& res) { Reply(res, h.Robots()); }));
  s.Get("/api/v1/traffic", Guarded(auth, Access::kReadFleet,
                                   [&h](const httplib::Request&, httplib::Response& res) { Reply(res, h.Traffic()); }));
  s.Get(R"(/api/v1/robots/([^/]+))",
        Guarded(auth, Access::kReadFleet,
                [&h](const httplib::Request& req, httplib::Response& res) { Reply(res, h.Robot(req.matches[1])); }));
  s.Get("/api/v1/session", [auth](const httplib::Request& req, httplib::Response& res) {
    // Who the token is: every role may ask (kReadMap is every role's); 401 without a valid one.
    const bool given = req.has_header("Authorization");
    const std::string value = given ? req.get_header_value("Authorization") : std::string();
    Authenticator::Outcome who;
    if (auth) who = auth->Authorize(given ? std::optional<std::string_view>(value) : std::nullopt, Access::kReadMap);
    if (!who.status.ok()) {
      res.set_header("WWW-Authenticate", "Bearer");
      Reply(res, {HttpStatus(who.status.code), RestHandlers::ErrorBody(who.status.message)});
      return;
    }
    Reply(res, RestHandlers::Session(who.principal, auth && auth->enabled()));
  });
  using engine::RobotCommandKind;
  for (const auto& [path, kind] : {std::pair{"pause", RobotCommandKind::kPause},
                                   std::pair{"resume", RobotCommandKind::kResume},
                                   std::pair{"out-of-service", RobotCommandKind::kTakeOutOfService},
                                   std::pair{"return-to-service", RobotCommandKind::kReturnToService},
                                   std::pair{"clear", RobotCommandKind::kClear}}) {
    s.Post(std::string(R"(/api/v1/robots/([^/]+)/)") + path,
           Guarded(auth, Access::kRobotCommand,
                   ActorHandler([&h, kind = kind](const httplib::Request& req, httplib::Response& res,
                                                  const std::string& actor) {
                     Reply(res, h.CommandRobot(kind, req.matches[1], actor));
                   })));
  }
  s.Post(R"(/api/v1/robots/([^/]+)/send)",
         Guarded(auth, Access::kRobotCommand,
                 ActorHandler([&h](const httplib::Request& req, httplib::Response& res, const std::string& actor) {
                   if (JsonBody(req, res)) Reply(res, h.SendRobot(req.matches[1], req.body, actor));
                 })));
  s.Get("/api/v1/orders", Guarded(auth, Access::kReadOrders, [&h](const httplib::Request& req, httplib::Response& res) {
          std::optional<std::string> state, finished;
          if (req.has_param("state")) state = req.get_param_value("state");
          if (req.has_param("finished")) finished = req.get_param_value("finished");
          Reply(res, h.Orders(state, finished));
        }));
  s.Get(R"(/api/v1/orders/([^/]+))",
        Guarded(auth, Access::kReadOrders,
                [&h](const httplib::Request& req, httplib::Response& res) { Reply(res, h.Order(req.matches[1])); }));
  s.Post("/api/v1/orders",
         Guarded(auth, Access::kSubmitOrder,
                 ActorHandler([&h](const httplib::Request& req, httplib::Response& res, const std::string& actor) {
                   if (JsonBody(req, res)) Reply(res, h.SubmitOrder(req.body, actor));
                 })));
  s.Delete(R"(/api/v1/orders/([^/]+))",
           Guarded(auth, Access::kCancelOrder,
                   ActorHandler([&h](const httplib::Request& req, httplib::Response& res, const std::string& actor) {
                     Reply(res, h.CancelOrder(req.matches[1],
                                              req.has_param("reason") ? req.get_param_value("reason") : "", actor));
                   })));
  if (!web_root.empty()) ServeWebRoot(s, web_root);
  s.set_payload_max_length(kMaxBodyBytes);
  s.new_task_queue = [] { return new httplib::ThreadPool(kHttpThreads); };
  s.set_read_timeout(kReadTimeoutSeconds);
  s.set_keep_alive_timeout(kKeepAliveSeconds);
  // Headers and body leave in two writes: with Nagle's algorithm the second waits for the
  // client's delayed ACK (40 ms per request on keep-alive connections, measured).
  s.set_tcp_nodelay(true);
  s.set_error_handler([](const httplib::Request& req, httplib::Response& res) {
    if (!res.body.empty()) return;
    std::string message;
    switch (res.status) {
      case 400: message = "malformed HTTP request"; break;
      case 404: message = "no such endpoint: " + req.method + " " + req.path; break;
      case 413: message = "request body too large: the limit is " + std::to_string(kMaxBodyBytes) + " bytes"; break;
      case 414: message = "request URI too long"; break;
      default: message = "request failed with HTTP " + std::to_string(res.status);
    }
    res.set_content(RestHandlers::ErrorBody(message), "application/json");
  });
  s.set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr ep) {
    std::string what = "internal error";
    try {
      if (ep) std::rethrow_exception(ep);
    } catch (const std::exception& e) {
      what = e.what();
    } catch (...) {
    }
    res.status = 500;
    res.set_content(RestHandlers::ErrorBody(what), "application/json");
  });
}

RestServer::~RestServer() { Stop(); }

bool RestServer::valid() const { return http_->is_valid(); }

int RestServer::Start(const std::string& bind, int port) {
  int bound = port;
  if (port == 0) {
    bound = http_->bind_to_any_port(bind);
  } else if (!http_->bind_to_port(bind, port)) {
    bound = -1;
  }
  if (bound <= 0) return -1;
  listening_ = true;
  thread_ = std::thread([this] {
    http_->listen_after_bind();
    listening_ = false;
  });
  return bound;
}

void RestServer::Stop() {
  // httplib's stop() does nothing until the listener thread runs (is_running()), so a Stop
  // right after Start repeats it until the listener has returned.
  while (listening_) {
    http_->stop();
    if (listening_) std::this_thread::yield();
  }
  if (thread_.joinable()) thread_.join();
}

}  // namespace dispatch::server
