// order-load: the order-intake benchmark client (issue 6 §4). Submits N random orders to
// OrderService.SubmitOrder from C threads at once over one channel and prints the
// throughput and the latency distribution of the calls (every call must succeed).
//   order-load --server HOST:PORT --orders 2000 --concurrency 8 [--picks 1] [--seed 1]
//              [--json FILE]
// Orders: `picks` random pick points and a random drop point of the served map (GetMap),
// client ids "<run>-<i>" with a run tag that is new each time (so repeats are not
// idempotent replays), priority 0, no formations. Exit status 0 when every call succeeded.
#include <grpcpp/grpcpp.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "clients/client_security.h"
#include "warehouse/dispatch/v1/map.grpc.pb.h"
#include "warehouse/dispatch/v1/orders.grpc.pb.h"

namespace dispatch::clients {
namespace {

namespace v1 = ::warehouse::dispatch::v1;
using Clock = std::chrono::steady_clock;

double Percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5);
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

int Main(int argc, char** argv) {
  CLI::App app{"order-load: SubmitOrder throughput and latency"};
  std::string server = "127.0.0.1:50051", json_out;
  std::size_t orders = 1000, concurrency = 4, picks = 1;
  unsigned seed = 1;
  app.add_option("--server", server, "dispatchd gRPC address HOST:PORT")->capture_default_str();
  app.add_option("--orders", orders, "Orders to submit")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--concurrency", concurrency, "Calls in flight (threads)")->capture_default_str()
      ->check(CLI::Range(std::size_t{1}, std::size_t{1024}));
  app.add_option("--picks", picks, "Pick points per order")->capture_default_str()
      ->check(CLI::Range(std::size_t{1}, std::size_t{10}));
  app.add_option("--seed", seed, "Random seed for the stops")->capture_default_str();
  app.add_option("--json", json_out, "Write the figures as JSON here");
  ClientSecurity security;
  AddSecurityOptions(app, security);
  CLI11_PARSE(app, argc, argv);
  if (std::string error; !Resolve(security, error)) {
    std::fprintf(stderr, "order-load: %s\n", error.c_str());
    return 2;
  }

  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(512 << 20);  // GetMap of a large grid floor
  auto channel = grpc::CreateCustomChannel(server, Credentials(security), args);
  v1::GetMapResponse map;
  {
    grpc::ClientContext ctx;
    Authorize(ctx, security.token);
    ctx.set_wait_for_ready(true);
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    const grpc::Status s = v1::MapService::NewStub(channel)->GetMap(&ctx, {}, &map);
    if (!s.ok()) {
      std::fprintf(stderr, "order-load: GetMap from %s failed: %s\n", server.c_str(), s.error_message().c_str());
      return 1;
    }
  }
  std::vector<std::string> pick_points, drop_points;
  for (const v1::MapPoint& p : map.map().points()) {
    if (p.kind() == v1::POINT_KIND_PICK) pick_points.push_back(p.name());
    if (p.kind() == v1::POINT_KIND_DROP) drop_points.push_back(p.name());
  }
  if (pick_points.empty() || drop_points.empty()) {
    std::fprintf(stderr, "order-load: map '%s' has %zu pick and %zu drop points; it needs both\n",
                 map.map().name().c_str(), pick_points.size(), drop_points.size());
    return 1;
  }
  std::vector<v1::SubmitOrderRequest> requests(orders);
  std::mt19937 rng(seed);
  const std::string run = "load-" + std::to_string(std::chrono::system_clock::now().time_since_epoch().count());
  for (std::size_t i = 0; i < orders; ++i) {
    v1::SubmitOrderRequest& r = requests[i];
    r.set_client_order_id(run + "-" + std::to_string(i));
    for (std::size_t k = 0; k < picks; ++k) {
      r.add_picks()->set_point_name(pick_points[rng() % pick_points.size()]);
    }
    r.mutable_drop()->set_point_name(drop_points[rng() % drop_points.size()]);
  }

  auto stub = v1::OrderService::NewStub(channel);
  std::atomic<std::size_t> next{0};
  std::mutex mu;
  std::vector<double> latencies_ms;
  latencies_ms.reserve(orders);
  std::size_t failures = 0;
  std::string first_failure;
  const Clock::time_point start = Clock::now();
  std::vector<std::thread> threads;
  for (std::size_t t = 0; t < concurrency; ++t) {
    threads.emplace_back([&] {
      std::vector<double> mine;
      for (std::size_t i = next++; i < orders; i = next++) {
        grpc::ClientContext ctx;
        ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
        Authorize(ctx, security.token);
        v1::SubmitOrderResponse response;
        const Clock::time_point sent = Clock::now();
        const grpc::Status s = stub->SubmitOrder(&ctx, requests[i], &response);
        mine.push_back(std::chrono::duration<double, std::milli>(Clock::now() - sent).count());
        if (!s.ok()) {
          std::lock_guard<std::mutex> lock(mu);
          if (failures++ == 0) first_failure = requests[i].client_order_id() + ": " + s.error_message();
        }
      }
      std::lock_guard<std::mutex> lock(mu);
      latencies_ms.insert(latencies_ms.end(), mine.begin(), mine.end());
    });
  }
  for (auto& t : threads) t.join();
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  const double p50 = Percentile(latencies_ms, 0.5), p99 = Percentile(latencies_ms, 0.99),
               max = Percentile(latencies_ms, 1.0);
  std::printf("order-load: %zu orders in %.2f s with %zu in flight: %.0f orders/s; latency p50 %.2f ms, "
              "p99 %.2f ms, max %.2f ms; %zu failed\n",
              orders, seconds, concurrency, static_cast<double>(orders) / seconds, p50, p99, max, failures);
  if (failures) std::fprintf(stderr, "order-load: first failure: %s\n", first_failure.c_str());
  if (!json_out.empty()) {
    std::ofstream out(json_out, std::ios::trunc);
    out << "{\"orders\": " << orders << ", \"concurrency\": " << concurrency << ", \"seconds\": " << seconds
        << ", \"orders_per_second\": " << static_cast<double>(orders) / seconds << ", \"p50_ms\": " << p50
        << ", \"p99_ms\": " << p99 << ", \"max_ms\": " << max << ", \"failed\": " << failures << "}\n";
    if (!out) {
      std::fprintf(stderr, "order-load: cannot write %s\n", json_out.c_str());
      return 1;
    }
  }
  return failures ? 2 : 0;
}

}  // namespace
}  // namespace dispatch::clients

int main(int argc, char** argv) { return dispatch::clients::Main(argc, argv); }
