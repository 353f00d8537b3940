// Only httplib and the Eigen-free rest_handlers.h here (see rest_handlers.h).
#include "server/rest_api.h"

#include <httplib.h>

namespace dispatch::server {
namespace {

void Reply(httplib::Response& res, const RestReply& reply) {
  res.status = reply.status;
  res.set_content(reply.body.dump(), "application/json");
}

}  // namespace

RestServer::RestServer(RestHandlers handlers)
    : handlers_(handlers), http_(std::make_unique<httplib::Server>()) {
  auto& h = handlers_;
  auto& s = *http_;
  s.Get("/healthz", [&h](const httplib::Request&, httplib::Response& res) { Reply(res, h.Health()); });
  s.Get("/readyz", [&h](const httplib::Request&, httplib::Response& res) { Reply(res, h.Ready()); });
  s.Get("/api/v1/status", [&h](const httplib::Request&, httplib::Response& res) { Reply(res, h.Status()); });
  s.Get("/api/v1/robots", [&h](const httplib::Request&, httplib::Response& res) { Reply(res, h.Robots()); });
  s.Get("/api/v1/traffic", [&h](const httplib::Request&, httplib::Response& res) { Reply(res, h.Traffic()); });
  s.Get(R"(/api/v1/robots/([^/]+))", [&h](const httplib::Request& req, httplib::Response& res) {
    Reply(res, h.Robot(req.matches[1]));
  });
  s.Get("/api/v1/orders", [&h](const httplib::Request& req, httplib::Response& res) {
    std::optional<std::string> state;
    if (req.has_param("state")) state = req.get_param_value("state");
    Reply(res, h.Orders(state));
  });
  s.Get(R"(/api/v1/orders/([^/]+))", [&h](const httplib::Request& req, httplib::Response& res) {
    Reply(res, h.Order(req.matches[1]));
  });
  s.Post("/api/v1/orders", [&h](const httplib::Request& req, httplib::Response& res) {
    Reply(res, h.SubmitOrder(req.body));
  });
  s.Delete(R"(/api/v1/orders/([^/]+))", [&h](const httplib::Request& req, httplib::Response& res) {
    Reply(res, h.CancelOrder(req.matches[1], req.has_param("reason") ? req.get_param_value("reason") : ""));
  });
  s.set_error_handler([](const httplib::Request& req, httplib::Response& res) {
    if (!res.body.empty()) return;
    const std::string message = res.status == 404 ? "no such endpoint: " + req.method + " " + req.path
                                                  : "request failed with HTTP " + std::to_string(res.status);
    res.set_content(nlohmann::json{{"error", message}}.dump(), "application/json");
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
    res.set_content(nlohmann::json{{"error", what}}.dump(), "application/json");
  });
}

RestServer::~RestServer() { Stop(); }

int RestServer::Start(const std::string& bind, int port) {
  int bound = port;
  if (port == 0) {
    bound = http_->bind_to_any_port(bind);
  } else if (!http_->bind_to_port(bind, port)) {
    bound = -1;
  }
  if (bound <= 0) return -1;
  thread_ = std::thread([this] { http_->listen_after_bind(); });
  return bound;
}

void RestServer::Stop() {
  if (http_) http_->stop();
  if (thread_.joinable()) thread_.join();
}

}  // namespace dispatch::server
