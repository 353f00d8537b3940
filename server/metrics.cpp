#include "server/metrics.h"

#include <prometheus/counter.h>
#include <prometheus/gauge.h>
#include <prometheus/histogram.h>
#include <prometheus/registry.h>
#include <prometheus/text_serializer.h>

#include <map>

#include "server/snapshot.h"

namespace dispatch::server {
namespace {

// Seconds: 100 us .. 10 s (allocation, DB writes).
prometheus::Histogram::BucketBoundaries LatencyBuckets() {
  return {0.0001, 0.00025, 0.0005, 0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1, 2.5, 5, 10};
}

// Dispatcher seconds a robot waits: 0.1 s .. 5 min.
prometheus::Histogram::BucketBoundaries WaitBuckets() {
  return {0.1, 0.25, 0.5, 1, 2, 5, 10, 20, 30, 60, 120, 300};
}

// Raises a counter to `total` (the snapshot's counts only grow).
void RaiseTo(prometheus::Counter& counter, double total) {
  if (total > counter.Value()) counter.Increment(total - counter.Value());
}

}  // namespace

ServiceMetrics::ServiceMetrics() : registry_(std::make_shared<prometheus::Registry>()) {
  auto& r = *registry_;
  allocation_ = &prometheus::BuildHistogram()
                     .Name("dispatch_allocation_seconds")
                     .Help("Wall time of one award: the allocation strategy run for one order")
                     .Register(r)
                     .Add({}, LatencyBuckets());
  grant_wait_ = &prometheus::BuildHistogram()
                     .Name("dispatch_grant_wait_seconds")
                     .Help("Dispatcher seconds a robot stood held (Hold) before its release (Resume)")
                     .Register(r)
                     .Add({}, WaitBuckets());
  db_write_ = &prometheus::BuildHistogram()
                   .Name("dispatch_db_write_seconds")
                   .Help("Wall time of one store write or transaction, by operation")
                   .Register(r);
  orders_ = &prometheus::BuildGauge().Name("dispatch_orders").Help("Orders by state").Register(r);
  robots_ = &prometheus::BuildGauge()
                 .Name("dispatch_robots")
                 .Help("Robots by state (offline when not connected)")
                 .Register(r);
  streams_ = &prometheus::BuildGauge()
                  .Name("dispatch_robot_streams")
                  .Help("Connected robot streams (FleetService.Connect)")
                  .Register(r)
                  .Add({});
  min_distance_ = &prometheus::BuildGauge()
                       .Name("dispatch_min_robot_distance_meters")
                       .Help("Smallest centre distance seen between robots of different agents (-1: none yet)")
                       .Register(r)
                       .Add({});
  auto counter = [&r](const char* name, const char* help) {
    return &prometheus::BuildCounter().Name(name).Help(help).Register(r).Add({});
  };
  grants_ = counter("dispatch_grants_total", "Releases sent to robots as Grant messages");
  holds_ = counter("dispatch_holds_total", "Hold messages sent to robots");
  replans_ = counter("dispatch_replans_total", "Legs re-planned by the traffic controller");
  deadlocks_ = counter("dispatch_deadlocks_resolved_total", "Wait-for cycles broken");
  head_on_ = counter("dispatch_head_on_conflicts_total", "Head-on conflicts on single lanes");
  nudges_ = counter("dispatch_nudges_total", "Idle robots sent aside for others");
  implausible_ = counter("dispatch_implausible_reports_total",
                         "Robot reports not taken: arrivals at unreleased or far waypoints, picks and drops away from the stop");
}

ServiceMetrics::~ServiceMetrics() = default;

void ServiceMetrics::ObserveAllocation(double seconds) { allocation_->Observe(seconds); }

void ServiceMetrics::ObserveGrantWait(double seconds) { grant_wait_->Observe(seconds); }

void ServiceMetrics::ObserveDbWrite(const std::string& op, double seconds) {
  prometheus::Histogram* h = nullptr;
  {
    std::lock_guard<std::mutex> lock(db_mu_);
    h = &db_write_->Add({{"op", op}}, LatencyBuckets());
  }
  h->Observe(seconds);
}

std::string ServiceMetrics::Render(const Snapshot& snap) {
  std::lock_guard<std::mutex> lock(render_mu_);
  std::map<std::string, double> orders, robots;
  for (auto s : {engine::OrderState::kAccepted, engine::OrderState::kAssigned, engine::OrderState::kInProgress,
                 engine::OrderState::kCompleted, engine::OrderState::kCancelled, engine::OrderState::kFailed}) {
    orders[engine::OrderStateName(s)] = 0;
  }
  for (auto s : {engine::RobotState::kIdle, engine::RobotState::kMoving, engine::RobotState::kWorking,
                 engine::RobotState::kWaiting, engine::RobotState::kParked, engine::RobotState::kCharging,
                 engine::RobotState::kFault, engine::RobotState::kOffline}) {
    robots[engine::RobotStateName(s)] = 0;
  }
  for (const auto& o : snap.orders) orders[engine::OrderStateName(o->record.order.state)] += 1;
  for (const auto& [state, n] : snap.finished_in_store) orders[engine::OrderStateName(state)] += static_cast<double>(n);
  double connected = 0;
  for (const auto& [id, r] : snap.robots) {
    robots[engine::RobotStateName(r.connected ? r.robot.state : engine::RobotState::kOffline)] += 1;
    connected += r.connected ? 1 : 0;
  }
  for (const auto& [state, n] : orders) orders_->Add({{"state", state}}).Set(n);
  for (const auto& [state, n] : robots) robots_->Add({{"state", state}}).Set(n);
  streams_->Set(connected);
  min_distance_->Set(snap.traffic.min_distance);
  RaiseTo(*grants_, static_cast<double>(snap.traffic.grants));
  RaiseTo(*holds_, static_cast<double>(snap.traffic.holds));
  RaiseTo(*replans_, static_cast<double>(snap.traffic.replans));
  RaiseTo(*deadlocks_, static_cast<double>(snap.traffic.deadlocks_resolved));
  RaiseTo(*head_on_, static_cast<double>(snap.traffic.head_on_conflicts));
  RaiseTo(*nudges_, static_cast<double>(snap.traffic.nudges));
  RaiseTo(*implausible_, static_cast<double>(snap.traffic.implausible_reports));
  return prometheus::TextSerializer().Serialize(registry_->Collect());
}

}  // namespace dispatch::server
