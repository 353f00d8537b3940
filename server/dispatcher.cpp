// Dispatcher: creation, recovery, the loop and publishing. The order commands are in
// dispatcher_orders.cpp, allocation rounds in dispatcher_allocation.cpp, carrying out the
// core's changes in dispatcher_commit.cpp, robot streams in dispatcher_robots.cpp, traffic
// control in dispatcher_traffic.cpp; the parts they use are robot_sessions.h (streams and
// message sequences), order_views.h (the order book), change_store.h (a change's store
// transaction), snapshot_builder.h and core_journal_writer.h.
#include "server/dispatcher.h"

#include <spdlog/spdlog.h>

#include <algorithm>

#include "engine/dispatch/strategy.h"
#include "server/json_convert.h"
#include "server/snapshot_builder.h"

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
  return core;
}

engine::Result<std::unique_ptr<Dispatcher>> Dispatcher::Create(
    std::shared_ptr<const engine::WarehouseMap> map, std::shared_ptr<const engine::RouteTable> routes,
    storage::Store& store, DispatcherOptions options) {
  if (!map || !routes) return engine::InvalidArgument("dispatcher: null map or route table");
  if (auto valid = engine::ValidateAllocationConfig(options.allocation); !valid.ok()) {
    return valid.error();
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
      rounds_(std::move(rounds)),
      core_(std::move(core)),
      wall_start_(Clock::now()),
      book_(options_.finished_retained),
      // Below the loop's priority: traffic control first when the cores are busy.
      route_worker_(std::make_unique<WorkerThread>(kWorkerNice)),
      allocation_worker_(std::make_unique<WorkerThread>(kWorkerNice)) {
  if (options_.journal) {
    journal_writer_ = std::make_unique<CoreJournalWriter>(*options_.journal, options_.journal_run,
                                                          options_.journal_max_bytes, kWorkerNice);
  }
}

Dispatcher::~Dispatcher() {
  // The workers post to the loop: they stop before anything is torn down.
  route_worker_->Stop();
  allocation_worker_->Stop();
  Stop();
  if (journal_writer_) journal_writer_->Stop();
}

engine::Status Dispatcher::Recover() {
  auto loaded = book_.Load(store_);
  if (!loaded.ok()) return loaded.error();
  time_base_ = std::max(time_base_, loaded->latest_time);
  last_order_number_ = std::max(last_order_number_, loaded->last_order_number);
  // The open orders enter the core with their robots.
  for (const auto& view : book_.all()) {
    const storage::OrderRecord& rec = view->record;
    if (!engine::IsTerminal(rec.order.state)) core_->AddOrder(rec.order, rec.robots);
  }
  // Robots (all offline until they reconnect) and their plans.
  auto robots = store_.ListRobots();
  if (!robots.ok()) return robots.error();
  auto assignments = store_.ListAssignments();
  if (!assignments.ok()) return assignments.error();
  std::map<std::string, engine::Assignment> plans;
  for (auto& a : *assignments) {
    time_base_ = std::max(time_base_, a.updated_time);
    plans[a.robot_id] = std::move(a);
  }
  for (auto& record : *robots) {
    const std::string id = record.robot.id;
    RobotSession& s = sessions_.Get(id);
    RestoreSession(s, record);
    s.offline_since = Clock::now();
    time_base_ = std::max(time_base_, record.last_seen);
    // On line when the old process stopped: where it is now is known when it reports.
    const bool was_on_line = options_.traffic_control && record.robot.state != engine::RobotState::kOffline;
    if (was_on_line) restart_wait_.Await(id);
    auto plan = plans.find(id);
    core_->RestoreRobot(std::move(record.robot),
                        plan == plans.end() ? std::nullopt : std::optional<engine::Assignment>(std::move(plan->second)),
                        !was_on_line);
  }
  std::uint64_t retired = 0;
  for (const auto& [state, n] : book_.finished_in_store()) retired += n;
  spdlog::info("recovered {} orders ({} finished ones left in the store), {} robots, {} assignments; "
               "dispatcher time {:.1f} s", book_.all().size(), retired, sessions_.size(), plans.size(), time_base_);
  if (restart_wait_.waiting()) {
    spdlog::info("traffic control waits up to {:.1f} s for the {} robots that were on line to report",
                 options_.heartbeat_timeout, restart_wait_.awaited().size());
  }
  return engine::Ok{};
}

void Dispatcher::Start() {
  if (started_.exchange(true)) return;
  restart_wait_.SetDeadline(Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                std::chrono::duration<double>(options_.heartbeat_timeout)));
  thread_ = std::thread([this] { Loop(); });
}

void Dispatcher::CloseStreams() {
  Post([this] {
    for (auto& [id, s] : sessions_) {
      if (auto link = sessions_.Detach(id)) {
        CloseLink(link, MakeStatus(StatusCode::kUnavailable, "dispatcher shutting down"));
        dirty_ = true;
      }
    }
  });
  hub_.CloseAll();
}

void Dispatcher::Stop() {
  if (!started_.load()) return;
  // Orders and rounds the workers still hold reach the loop's queue, which runs them.
  route_worker_->Stop();
  allocation_worker_->Stop();
  {
    std::lock_guard<std::mutex> lock(queue_mu_);
    if (stopping_) return;
  }
  CloseStreams();
  {
    std::lock_guard<std::mutex> lock(queue_mu_);
    stopping_ = true;
  }
  queue_cv_.notify_all();
  if (thread_.joinable()) thread_.join();
  WriteJournal();  // the last batch's entries
  if (journal_writer_) journal_writer_->Stop();
}

void Dispatcher::Post(std::function<void()> fn) {
  {
    std::lock_guard<std::mutex> lock(queue_mu_);
    queue_.push_back(std::move(fn));
  }
  queue_cv_.notify_one();
}

double Dispatcher::Now() const {
  const std::chrono::duration<double> elapsed = Clock::now() - wall_start_;
  return time_base_ + elapsed.count() * options_.time_scale;
}

void Dispatcher::Loop() {
  // Ticks also run the traffic controller for robots that report nothing new (a held point
  // frees up): at least 20 times per wall second; and the loop wakes when a robot's planned
  // departure comes (TrafficGate::NextWake).
  const double tick_s = std::clamp(options_.heartbeat_timeout / 10.0, 0.01, core_->gate() ? 0.05 : 0.5);
  const auto tick = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(tick_s));
  auto next_tick = Clock::now() + tick;
  for (;;) {
    std::deque<std::function<void()>> batch;
    bool stopping = false;
    {
      auto wake = dirty_ ? std::min(next_tick, last_publish_ + kPublishEvery) : next_tick;
      // A robot that only waits for its planned departure is released then, not a tick late.
      if (const engine::TrafficGate* gate = core_->gate()) {
        const double at = gate->NextWake();
        if (at < Now() + tick_s * options_.time_scale) {
          const auto wait = std::chrono::duration<double>(std::max(0.0, at - Now()) / options_.time_scale);
          wake = std::min(wake, Clock::now() + std::chrono::duration_cast<Clock::duration>(wait));
        }
      }
      std::unique_lock<std::mutex> lock(queue_mu_);
      queue_cv_.wait_until(lock, wake, [&] { return !queue_.empty() || stopping_; });
      batch.swap(queue_);
      stopping = stopping_;
    }
    for (auto& fn : batch) fn();
    if (Clock::now() >= next_tick) {
      Tick();
      next_tick = Clock::now() + tick;
    }
    StepTraffic();
    Flush();
    // Allocation runs once per batch, after the batch's replies are out: an order is
    // acknowledged when it is committed, and the orders of a burst are auctioned together.
    if (core_->TakeAllocationDue()) allocation_due_ = true;
    if (allocation_due_) {
      AllocatePending();
      StepTraffic();
      Flush();
    }
    if (stopping) {
      std::lock_guard<std::mutex> lock(queue_mu_);
      if (queue_.empty()) break;
    }
  }
}

void Dispatcher::Flush() {
  // Publish first, then let replies and journal events out: whoever hears of a change finds
  // it in the snapshot. Changes nobody is told about yet (robot reports, grants) are
  // published at most every kPublishEvery: a snapshot copies every robot and order, and 500
  // robots reporting at 10 Hz make hundreds of batches a second.
  if (book_.Retire(std::min(kRetireSlack, options_.finished_retained / 16))) dirty_ = true;  // small ones: exactly
  if (dirty_ && (deferred_need_publish_ || Clock::now() - last_publish_ >= kPublishEvery)) Publish();
  deferred_need_publish_ = false;
  std::vector<std::function<void()>> effects;
  effects.swap(deferred_);
  for (auto& effect : effects) effect();
  WriteJournal();
}

void Dispatcher::Publish() {
  SnapshotFacts facts;
  facts.version = ++snapshot_version_;
  facts.time = Now();
  facts.map_version = options_.map_version;
  facts.strategy = options_.strategy;
  facts.time_scale = options_.time_scale;
  facts.implausible_reports = implausible_;
  facts.awaiting_reconnect = &restart_wait_.awaited();
  facts.min_distance = min_distance_;
  std::atomic_store(&snapshot_, std::shared_ptr<const Snapshot>(BuildSnapshot(*map_, *core_, sessions_, book_, facts)));
  dirty_ = false;
  last_publish_ = Clock::now();
}

void Dispatcher::Journal(const storage::OrderEvent& event) {
  Defer([this, event] { hub_.Publish(event); });
}

void Dispatcher::Defer(std::function<void()> effect, bool after_publish) {
  deferred_.push_back(std::move(effect));
  deferred_need_publish_ = deferred_need_publish_ || after_publish;
}

void Dispatcher::CloseLink(const std::shared_ptr<RobotLink>& link, ServiceStatus status) {
  // After the publish: a robot (or test) that sees its stream end finds what it sent before
  // the end in the snapshot. Rare, so it costs nothing.
  Defer([link, status = std::move(status)] { link->Close(status); });
}

}  // namespace dispatch::server
