// Dispatcher: creation, recovery, the loop and publishing. The order commands are in
// dispatcher_orders.cpp, allocation rounds in dispatcher_allocation.cpp, carrying out the
// core's changes in dispatcher_commit.cpp, robot streams in dispatcher_robots.cpp, traffic
// control in dispatcher_traffic.cpp; the parts they use are named in dispatcher.h.
#include "server/dispatcher.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

#include "engine/dispatch/strategy.h"
#include "server/snapshot_builder.h"
#include "server/state_recovery.h"

namespace dispatch::server {
namespace {

constexpr int kWorkerNice = 5;  // the workers' CPU priority below the loop's (WorkerThread)

}  // namespace

engine::CoreOptions CoreOptionsOf(const DispatcherOptions& options) {
  engine::CoreOptions core;
  core.robot_snap_tolerance = options.robot_snap_tolerance;
  core.traffic_control = options.traffic_control;
  core.traffic = options.traffic;
  core.one_formation_per_pick = options.one_formation_per_pick;
  core.blocked_recovery = options.blocked_recovery;
  return core;
}

engine::Result<std::unique_ptr<Dispatcher>> Dispatcher::Create(
    std::shared_ptr<const engine::WarehouseMap> map, std::shared_ptr<const engine::RouteTable> routes,
    storage::Store& store, DispatcherOptions options) {
  if (!map || !routes) return engine::InvalidArgument("dispatcher: null map or route table");
  if (auto valid = engine::ValidateAllocationConfig(options.allocation); !valid.ok()) {
    return valid.error();
  }
  if (!std::isfinite(options.batch_window) || options.batch_window < 0) {
    return engine::InvalidArgument("dispatcher: batch_window must be >= 0 seconds");
  }
  auto allocator = engine::MakeAllocator(options.strategy);
  if (!allocator.ok()) return allocator.error();
  auto stopwatch = [] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  };
  auto rounds = std::make_unique<engine::RoundRunner>(map, routes, options.allocation,
                                                      std::move(allocator).value(), stopwatch);
  auto core = engine::DispatchCore::Create(map, routes, CoreOptionsOf(options));
  if (!core.ok()) return core.error();
  const bool journaled = options.journal != nullptr;
  std::unique_ptr<Dispatcher> d(new Dispatcher(
      std::move(map), std::move(routes), store, std::move(options), std::move(rounds),
      std::make_unique<engine::JournaledCore>(std::move(core).value(), journaled)));
  if (auto recovered = d->Recover(); !recovered.ok()) return recovered.error();
  d->Publish();
  return d;
}

Dispatcher::Dispatcher(std::shared_ptr<const engine::WarehouseMap> map,
                       std::shared_ptr<const engine::RouteTable> routes, storage::Store& store,
                       DispatcherOptions options, std::unique_ptr<engine::RoundRunner> rounds,
                       std::unique_ptr<engine::JournaledCore> core)
    : map_(std::move(map)),
      routes_(std::move(routes)),
      store_(store),
      options_(std::move(options)),
      core_(std::move(core)),
      clock_(options_.time_scale),
      book_(options_.finished_retained),
      // Below the loop's priority: traffic control first when the cores are busy.
      route_worker_(std::make_unique<WorkerThread>(kWorkerNice)),
      round_worker_(std::move(rounds), options_.allocation, kWorkerNice) {
  rounds_due_.SetWindow(options_.batch_window);
  if (options_.journal) {
    journal_writer_ = std::make_unique<CoreJournalWriter>(*options_.journal, options_.journal_run,
                                                          options_.journal_max_bytes, kWorkerNice);
  }
}

Dispatcher::~Dispatcher() {
  // The workers post to the loop: they stop before anything is torn down.
  route_worker_->Stop();
  round_worker_.Stop();
  Stop();
  if (journal_writer_) journal_writer_->Stop();
}

engine::Status Dispatcher::Recover() {
  auto recovered = RecoverState(store_, options_.traffic_control, book_, *core_, sessions_, restart_wait_);
  if (!recovered.ok()) return recovered.error();
  clock_.ContinueFrom(recovered->latest_time);
  last_order_number_ = recovered->last_order_number;
  if (restart_wait_.waiting()) {
    spdlog::info("traffic control waits up to {:.1f} s for the {} robots that were on line to report",
                 options_.heartbeat_timeout, restart_wait_.awaited().size());
  }
  return engine::Ok{};
}

void Dispatcher::Start() {
  if (started_.exchange(true)) return;
  restart_wait_.SetDeadline(Clock::now() + WallDuration(options_.heartbeat_timeout));
  thread_ = std::thread([this] { Loop(); });
}

void Dispatcher::CloseStreams() {
  Post([this] {
    for (auto& [id, s] : sessions_) {
      if (auto link = sessions_.Detach(id)) {
        CloseLink(link, MakeStatus(StatusCode::kUnavailable, "dispatcher shutting down"));
        effects_.MarkChanged();
      }
    }
    for (const auto& [link, opened] : awaiting_hello_) {
      CloseLink(link, MakeStatus(StatusCode::kUnavailable, "dispatcher shutting down"));
    }
    awaiting_hello_.clear();
  });
  hub_.CloseAll();
}

void Dispatcher::Stop() {
  if (!started_.load()) return;
  // Orders and rounds the workers still hold reach the loop's queue, which runs them.
  route_worker_->Stop();
  round_worker_.Stop();
  if (queue_.stopping()) return;
  CloseStreams();
  queue_.Stop();
  if (thread_.joinable()) thread_.join();
  WriteJournal();  // the last batch's entries
  if (journal_writer_) journal_writer_->Stop();
}

void Dispatcher::Loop() {
  // Ticks also run the traffic controller for robots that report nothing new (a held point
  // frees up): at least 20 times per wall second; and the loop wakes when a robot's planned
  // departure comes (TrafficGate::NextWake).
  const double tick_s = std::clamp(options_.heartbeat_timeout / 10.0, 0.01, core_->gate() ? 0.05 : 0.5);
  const auto tick = WallDuration(tick_s);
  auto next_tick = Clock::now() + tick;
  for (;;) {
    auto wake = effects_.WakeBy(next_tick);
    // A robot that only waits for its planned departure is released then, not a tick late.
    if (const engine::TrafficGate* gate = core_->gate()) {
      const double at = gate->NextWake();
      const auto wall = Clock::now();
      if (at < clock_.At(wall) + tick_s * options_.time_scale) wake = std::min(wake, clock_.WallAt(at, wall));
    }
    // A round waiting for the batch window starts when it ends (within the tick, so a long
    // window never becomes a wall time out of the clock's range).
    if (const double now = Now(); rounds_due_.Waiting(now) && rounds_due_.not_before() < now + tick_s * options_.time_scale) {
      wake = std::min(wake, clock_.WallAt(rounds_due_.not_before(), Clock::now()));
    }
    CommandQueue::Batch batch = queue_.Take(wake);
    for (auto& command : batch.commands) command();
    if (Clock::now() >= next_tick) {
      Tick();
      next_tick = Clock::now() + tick;
    }
    StepTraffic();
    Flush();
    // Allocation runs once per batch, after the batch's replies are out: an order is
    // acknowledged when it is committed, and the orders of a burst are auctioned together.
    if (core_->TakeAllocationDue()) rounds_due_.MarkDue();
    if (rounds_due_.due() && !rounds_due_.Waiting(Now())) {
      AllocatePending();
      StepTraffic();
      Flush();
    }
    if (batch.stopping && queue_.empty()) break;
  }
}

void Dispatcher::Flush() {
  // Publish first, then let replies and journal events out: whoever hears of a change finds
  // it in the snapshot (BatchEffects says when a publish is due).
  const std::size_t retire_slack = std::min(kRetireSlack, options_.finished_retained / 16);  // small ones: exactly
  if (book_.Retire(retire_slack)) effects_.MarkChanged();
  if (effects_.PublishDue(Clock::now())) Publish();
  effects_.RunDeferred();
  WriteJournal();
}

void Dispatcher::Publish() {
  const auto started = Clock::now();
  SnapshotFacts facts;
  facts.version = ++snapshot_version_;
  facts.time = Now();
  facts.map_version = options_.map_version;
  facts.strategy = options_.strategy;
  facts.time_scale = options_.time_scale;
  facts.implausible_reports = implausible_;
  facts.awaiting_reconnect = &restart_wait_.awaited();
  facts.min_distance = distances_.closest();
  std::atomic_store(&snapshot_, std::shared_ptr<const Snapshot>(BuildSnapshot(*map_, *core_, sessions_, book_, facts)));
  const auto now = Clock::now();
  effects_.Published(now, now - started);
}

void Dispatcher::Journal(const storage::OrderEvent& event) {
  effects_.Announce([this, event] { hub_.Publish(event); });
}

void Dispatcher::CloseLink(const std::shared_ptr<RobotLink>& link, ServiceStatus status) {
  // After the publish: a robot (or test) that sees its stream end finds what it sent before
  // the end in the snapshot. Rare, so it costs nothing.
  Defer([link, status = std::move(status)] { link->Close(status); });
}

}  // namespace dispatch::server
