// ServiceMetrics: dispatchd's Prometheus metrics (issue 6 §2, SPEC §4 "/metrics") on a
// prometheus-cpp registry, rendered in the text exposition format (0.0.4) for GET /metrics.
//
// Observed as they happen (thread-safe; prometheus-cpp histograms lock):
//   dispatch_allocation_seconds         wall time of one award (the strategy run for one order)
//   dispatch_grant_wait_seconds         dispatcher seconds a robot stood held before its release
//   dispatch_db_write_seconds{op}       wall time of one store write (or one transaction)
// Read from the dispatcher's snapshot at every scrape:
//   dispatch_orders{state}              orders by state
//   dispatch_robots{state}              robots by state (offline when not connected)
//   dispatch_robot_streams              connected robot streams
//   dispatch_grants_total, dispatch_holds_total, dispatch_replans_total,
//   dispatch_deadlocks_resolved_total, dispatch_head_on_conflicts_total, dispatch_nudges_total,
//   dispatch_implausible_reports_total
//   dispatch_min_robot_distance_meters  closest two robots of different agents so far
#pragma once

#include <memory>
#include <mutex>
#include <string>

namespace prometheus {
class Registry;
class Histogram;
class Counter;
class Gauge;
template <typename T>
class Family;
}  // namespace prometheus

namespace dispatch::server {

struct Snapshot;

class ServiceMetrics {
 public:
  ServiceMetrics();
  ~ServiceMetrics();
  ServiceMetrics(const ServiceMetrics&) = delete;
  ServiceMetrics& operator=(const ServiceMetrics&) = delete;

  void ObserveAllocation(double seconds);
  void ObserveGrantWait(double seconds);
  // op: the store method, e.g. "insert_order", "transaction".
  void ObserveDbWrite(const std::string& op, double seconds);

  // Every metric in the text format, the snapshot's values brought up to date first.
  std::string Render(const Snapshot& snapshot);

 private:
  std::shared_ptr<prometheus::Registry> registry_;
  prometheus::Histogram* allocation_;
  prometheus::Histogram* grant_wait_;
  prometheus::Family<prometheus::Histogram>* db_write_;
  prometheus::Family<prometheus::Gauge>* orders_;
  prometheus::Family<prometheus::Gauge>* robots_;
  prometheus::Gauge* streams_;
  prometheus::Gauge* min_distance_;
  prometheus::Counter* grants_;
  prometheus::Counter* holds_;
  prometheus::Counter* replans_;
  prometheus::Counter* deadlocks_;
  prometheus::Counter* head_on_;
  prometheus::Counter* nudges_;
  prometheus::Counter* implausible_;
  std::mutex render_mu_;  // one scrape at a time brings the snapshot values up to date
  std::mutex db_mu_;      // db_write_ label lookups
};

}  // namespace dispatch::server
