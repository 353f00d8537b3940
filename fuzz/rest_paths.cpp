// REST requests, paths and query strings above all (issue 18 §5), through a real dispatchd
// (DispatchServer on 127.0.0.1, ephemeral ports, a SQLite file in a temporary folder, the
// Chu2024 floor, no tokens) over a real socket: the path's parameters (order and robot ids,
// `state`, `finished`, `reason`, `active`), percent escapes, the web map's files and whatever
// else the request line holds reach cpp-httplib's parser, its routing and our handlers.
//
// Input: byte 0 picks the method (GET, POST, DELETE, PUT, HEAD, OPTIONS), then the request
// target up to the first newline (at most 8 KiB), then the body (sent with Content-Type
// application/json). Checks: the service answers with an HTTP status line or closes the
// connection, never a 5xx other than 503 (a handler that failed is a bug; 503 is a store or
// readiness answer), and neither crashes nor trips a sanitizer.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>

#include "fuzz/fuzz_input.h"
#include "server/server.h"

namespace {

class Service {
 public:
  Service() {
    char folder[] = "/tmp/dispatch-fuzz-rest-XXXXXX";
    if (!mkdtemp(folder)) std::abort();
    folder_ = folder;
    dispatch::server::ServerConfig config;
    config.bind = "127.0.0.1";
    config.grpc_port = 0;
    config.http_port = 0;
    config.db = folder_ + "/dispatch.db";
    config.log_level = "critical";
    auto started = dispatch::server::DispatchServer::Start(config);
    if (!started.ok()) {
      std::fprintf(stderr, "rest_paths: dispatchd did not start: %s\n", started.error().message.c_str());
      std::abort();
    }
    server_ = std::move(started).value();
  }
  ~Service() {
    server_.reset();
    std::error_code ec;
    std::filesystem::remove_all(folder_, ec);
  }
  int port() const { return server_->ports().http; }

 private:
  std::string folder_;
  std::unique_ptr<dispatch::server::DispatchServer> server_;
};

Service& TheService() {
  static Service service;
  return service;
}

// Sends `request` on a new connection and returns what came back (up to 64 KiB is enough for
// the status line; the rest is read and dropped so the server is not blocked writing).
std::string Exchange(int port, const std::string& request) {
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  // Connects, giving the system a moment when it runs short of ports or queue room (tens of
  // thousands of connections a minute): a service that stays unreachable for 5 s is a failure.
  int fd = -1;
  for (int attempt = 0;; ++attempt) {
    fd = socket(AF_INET, SOCK_STREAM, 0);
    if (fd < 0) std::abort();
    timeval timeout{10, 0};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
    linger reset{1, 0};  // closed with a reset: no TIME_WAIT left behind on this side
    setsockopt(fd, SOL_SOCKET, SO_LINGER, &reset, sizeof reset);
    if (connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0) break;
    const int error = errno;
    close(fd);
    if (attempt == 50) {
      std::fprintf(stderr, "rest_paths: cannot connect to the service: %s\n", std::strerror(error));
      std::abort();
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));  // a transient shortage
  }
  std::size_t sent = 0;
  while (sent < request.size()) {
    const ssize_t n = send(fd, request.data() + sent, request.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) break;  // the server may close early on a malformed request
    sent += static_cast<std::size_t>(n);
  }
  shutdown(fd, SHUT_WR);
  std::string reply;
  std::array<char, 16384> buf{};
  for (;;) {
    const ssize_t n = recv(fd, buf.data(), buf.size(), 0);
    if (n <= 0) break;
    if (reply.size() < 65536) reply.append(buf.data(), static_cast<std::size_t>(n));
  }
  close(fd);
  return reply;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static constexpr const char* kMethods[] = {"GET", "POST", "DELETE", "PUT", "HEAD", "OPTIONS"};
  if (size == 0) return 0;
  const std::string_view in = dispatch::fuzz::Text(data + 1, size - 1);
  const char* method = kMethods[data[0] % std::size(kMethods)];
  const std::size_t eol = in.find('\n');
  std::string target(in.substr(0, std::min<std::size_t>(eol, 8192)));
  const std::string body(eol == std::string_view::npos ? std::string_view() : in.substr(eol + 1));
  if (target.empty() || target[0] != '/') target.insert(0, "/");
  const std::string request = std::string(method) + " " + target + " HTTP/1.1\r\nHost: fuzz\r\nConnection: close\r\n" +
                              "Content-Type: application/json\r\nContent-Length: " + std::to_string(body.size()) +
                              "\r\n\r\n" + body;
  const std::string reply = Exchange(TheService().port(), request);
  // "HTTP/1.1 NNN ...": a 5xx other than 503 means a handler failed.
  if (reply.size() >= 12 && reply.compare(0, 5, "HTTP/") == 0) {
    const std::size_t sp = reply.find(' ');
    const int status = sp == std::string::npos ? 0 : std::atoi(reply.c_str() + sp + 1);
    if (status >= 500 && status != 503) {
      std::fprintf(stderr, "rest_paths: %s %s answered %d:\n%s\n", method, target.c_str(), status,
                   reply.substr(0, 2000).c_str());
      std::abort();
    }
  }
  return 0;
}
