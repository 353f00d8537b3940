// Dispatcher: the service's adapter around the dispatch core (engine/dispatch/dispatch_core.h,
// which owns what orders, plans, robots and traffic mean), and the one writer of its state
// (SPEC §4 "Concurrency").
//
// One loop thread owns the core, the order views and the robot sessions. API threads never
// touch them: they post commands (Post, command_queue.h) and get the answer through a callback
// run on the loop thread (gRPC reactors finish from it; REST waits on a future, see Call). The
// loop publishes an immutable Snapshot (snapshot_builder.h) that reads use without locks: after
// every batch whose replies, journal events, Welcomes or stream ends announce a change (they go
// out only after that publish: read-your-writes, batch_effects.h), otherwise at most every
// 20 ms while robots report.
//
// Durability: an order is in the Store before SubmitOrder answers OK; every core change (an
// award with its explanation, a transition, new plans, the robots' reserved message sequences)
// is stored in one transaction (change_store.h) before the core and the views take it, and a
// failed write changes nothing. At start the orders, explanations, robots and plans are
// recovered from the store (state_recovery.h). Time is dispatcher seconds (dispatch_clock.h).
//
// Allocation (dispatcher_allocation.cpp): after a batch in which the core says a round is due,
// and once the previous round is committed (round_schedule.h), the core's round inputs go to
// the round worker (round_worker.h), which runs the strategy (engine::RoundRunner) off the
// loop; back on the loop the awards that still hold are committed, a few per loop turn. So
// traffic control never waits for an auction. New orders' route searches run on another
// worker before the loop sees the order; what the order commands answer is order_replies.h.
//
// Robots (dispatcher_robots.cpp, robot_sessions.h; the stream's rules: robot_protocol.h):
// Hello registers the robot at the map point its pose snaps to; its reports go to the core,
// the core's messages (plans, Grants, Holds, Resumes, PlanUpdates, cancels) to its stream,
// numbered over the robot's life. After every batch the core's traffic gate steps
// (dispatcher_traffic.cpp; the closest approach of two robots: distance_watch.h); a robot
// blocked with no way out, or offline for offline_grace after heartbeat_timeout of silence,
// loses its orders (the core's PlanLoss: assigned ones are re-allocated, in-progress ones fail).
//
// Restart (restart_wait.h): robots stored offline are obstacles at their stored points until
// they reconnect; until every robot the old process had on line has reported, or
// heartbeat_timeout has passed, the gate releases nothing; those still away are then placed at
// their stored points. /api/v1/status lists whom the wait is for (traffic.awaiting_reconnect).
//
// The core's journal (core_journal_writer.h) is written off the loop, batch by batch.
//
// Thread safety: the public methods are thread-safe; everything else runs on the loop thread.
#pragma once

#include <atomic>
#include <functional>
#include <future>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "engine/dispatch/allocation_round.h"
#include "engine/dispatch/journaled_core.h"
#include "engine/fleet/order.h"
#include "engine/routing/route_table.h"
#include "server/batch_effects.h"
#include "server/command_queue.h"
#include "server/core_journal_writer.h"
#include "server/dispatch_clock.h"
#include "server/distance_watch.h"
#include "server/memory_trim.h"
#include "server/metrics.h"
#include "server/order_replies.h"
#include "server/order_views.h"
#include "server/restart_wait.h"
#include "server/robot_link.h"
#include "server/robot_sessions.h"
#include "server/round_schedule.h"
#include "server/round_worker.h"
#include "server/service_status.h"
#include "server/snapshot.h"
#include "server/watch_hub.h"
#include "server/worker_thread.h"
#include "storage/journal_store.h"
#include "storage/store.h"

namespace dispatch::server {

struct DispatcherOptions {
  engine::AllocationConfig allocation;
  std::string strategy = "auction";  // auction | greedy | exact | psoga (MakeAllocator)
  double batch_window = 0.0;         // dispatcher s between round starts at least (RoundSchedule)
  double time_scale = 1.0;           // dispatcher seconds per wall second
  double heartbeat_interval = 1.0;   // wall seconds
  double heartbeat_timeout = 5.0;    // wall seconds
  double offline_grace = 10.0;       // wall seconds
  engine::SnapOptions snap;          // order stops
  double robot_snap_tolerance = 1.0;  // metres from a Hello pose to its nearest point
  // Finished orders kept in memory (the newest by finish time) besides every open one; the
  // others are read from the store when asked for (FindAnywhere, ListOrders).
  std::size_t finished_retained = 1000;
  std::string map_version;
  // Traffic control (engine/traffic/traffic_gate.h): waypoints released point by point
  // through the engine's TrafficController. Off: every waypoint is sent released (no grants or holds).
  bool traffic_control = true;
  engine::TrafficControllerConfig traffic;
  bool one_formation_per_pick = false;  // engine::CoreOptions::one_formation_per_pick
  double blocked_recovery = 60.0;       // engine::CoreOptions::blocked_recovery
  // Where allocation latency and grant waits are observed (optional; must outlive the
  // dispatcher).
  ServiceMetrics* metrics = nullptr;
  // The core's journal (issue 15 §4; optional, must outlive the dispatcher): every core call
  // of this run (journal_run, begun by the owner), written after every loop batch on a worker
  // of its own. Recording stops, and the run is marked truncated, once journal_max_bytes of
  // entries are written (0: no limit).
  storage::JournalStore* journal = nullptr;
  std::int64_t journal_run = 0;
  std::uint64_t journal_max_bytes = 0;
};

// The dispatch core the dispatcher builds for `options` (its journal's setup records the same).
engine::CoreOptions CoreOptionsOf(const DispatcherOptions& options);

using engine::OrderRoutes;
using engine::RouteWaypoint;

class Dispatcher {
 public:
  // Recovers the state from `store` (which must outlive the dispatcher). Errors: bad
  // options, unreadable store.
  static engine::Result<std::unique_ptr<Dispatcher>> Create(
      std::shared_ptr<const engine::WarehouseMap> map,
      std::shared_ptr<const engine::RouteTable> routes, storage::Store& store,
      DispatcherOptions options);
  ~Dispatcher();
  Dispatcher(const Dispatcher&) = delete;
  Dispatcher& operator=(const Dispatcher&) = delete;

  void Start();
  // Finishes every robot stream and WatchOrders stream (UNAVAILABLE); the loop keeps running.
  void CloseStreams();
  // Closes the streams, runs the commands already queued, stops the loop. Idempotent.
  void Stop();

  std::shared_ptr<const Snapshot> snapshot() const { return std::atomic_load(&snapshot_); }
  WatchHub& watch_hub() { return hub_; }
  storage::Store& store() { return store_; }
  const engine::WarehouseMap& map() const { return *map_; }
  const DispatcherOptions& options() const { return options_; }

  // --- Orders (callbacks run on the loop thread; they must not block) ------------------
  // `actor`: who asks (the token's name, server/auth.h; "" without tokens), journaled with the
  // events the call makes.
  void SubmitOrder(engine::OrderRequest request, std::string actor, std::function<void(SubmitReply)> done);
  // A reason longer than kMaxCancelReasonBytes is refused (INVALID_ARGUMENT).
  void CancelOrder(std::string order_id, std::string reason, std::string actor,
                   std::function<void(OrderReply)> done);
  static constexpr std::size_t kMaxCancelReasonBytes = 1024;

  // --- Operator commands (issue 18 §4) --------------------------------------------------
  // Carries out `kind` on robot `robot_id` for `actor` (the token's name; engine
  // DispatchCore::PlanCommand): pause, resume, out of service, return to service, clear, send
  // (to `station`: a parking or charging station's name, or the name of a park or charge
  // point). Stored with the robot (its marks, kept across restarts) and the orders it gives
  // back (their events name the actor), then applied. `done` runs once the snapshot shows it.
  // Errors: NOT_FOUND (robot, station), FAILED_PRECONDITION (the core's refusals),
  // UNAVAILABLE (the store failed: nothing changed).
  void CommandRobot(engine::RobotCommandKind kind, std::string robot_id, std::string station, std::string actor,
                    std::function<void(ServiceStatus)> done);

  // --- Robot streams -----------------------------------------------------------------
  // A stream opened: it must say Hello within heartbeat_timeout or it is ended
  // (DEADLINE_EXCEEDED), so streams that never say who they are do not pile up (issue 18 §3).
  void OnRobotStreamOpened(std::shared_ptr<RobotLink> link);
  // Every message of a stream, Hello first. Replies go to `link`.
  void OnRobotMessage(std::shared_ptr<RobotLink> link, RobotInbound message);
  // The stream ended (client gone or cancelled).
  void OnRobotGone(std::shared_ptr<RobotLink> link);

  // Loop thread only (e.g. from Call): each robot's traffic state in one line.
  std::vector<std::pair<std::string, std::string>> TrafficLines() const;
  // Loop thread only: the waypoints of `order_id` its robots have not reached yet.
  OrderRoutes RoutesOf(const std::string& order_id) const;
  // Any thread: the order with server id (or, by_client_id, client order id) `key`: from the
  // snapshot, else from the store (a finished order beyond DispatcherOptions::finished_retained;
  // with `explain` its allocation explanation is read from the journal). nullptr when there is
  // no such order; an error when the store cannot be read.
  engine::Result<std::shared_ptr<const OrderView>> FindAnywhere(const std::string& key, bool by_client_id,
                                                                bool explain) const;

  // Runs `fn` on the loop thread.
  void Post(std::function<void()> fn) { queue_.Post(std::move(fn)); }
  // Runs `fn` on the loop thread and waits for its result (for threads that may block,
  // e.g. REST handlers).
  template <class T>
  T Call(std::function<void(std::function<void(T)>)> fn) {
    auto promise = std::make_shared<std::promise<T>>();
    auto future = promise->get_future();
    Post([fn = std::move(fn), promise] { fn([promise](T value) { promise->set_value(std::move(value)); }); });
    return future.get();
  }

 private:
  using Clock = RobotSession::Clock;

  Dispatcher(std::shared_ptr<const engine::WarehouseMap> map,
             std::shared_ptr<const engine::RouteTable> routes, storage::Store& store,
             DispatcherOptions options, std::unique_ptr<engine::RoundRunner> rounds,
             std::unique_ptr<engine::JournaledCore> core);
  engine::Status Recover();
  void Loop();
  double Now() const { return clock_.Now(); }

  // Orders (dispatcher_orders.cpp).
  void DoSubmit(const engine::OrderRequest& request, const std::string& actor,
                const std::function<void(SubmitReply)>& done);
  ServiceStatus DoCommand(engine::OperatorCommand command, const std::string& station);
  void DoCancel(const std::string& order_id, const std::string& reason, const std::string& actor,
                const std::function<void(OrderReply)>& done);
  std::string NextOrderId();

  // Carrying out the core's changes (dispatcher_commit.cpp). Commit stores `change` in one
  // transaction (journal, plans, the robots' reserved message sequences; with `round` the
  // awards' explanations), then applies it to the core and the order views and sends its
  // messages. False (and *status) when the store failed: nothing changed.
  // `actor`: who made it (the token name of an operator's or WMS's call; "" the dispatcher).
  bool Commit(const engine::Change& change, const ServerRound* round, ServiceStatus* status = nullptr,
              const std::string& actor = "");
  // The robot as stored: the core's robot and the session.
  storage::RobotRecord RecordOf(const std::string& robot_id) const;
  // Stamps the robot's next message sequence and the time, and sends if connected (with
  // `after_publish` once the snapshot is published, see Defer).
  void SendTo(const std::string& robot_id, RobotOutbound message, bool after_publish = false);
  void Send(std::vector<engine::RobotCommand> commands, bool after_publish = false);
  // Publishes a committed journal event to the watchers after the next snapshot, which it does
  // not hasten (BatchEffects::Announce).
  void Journal(const storage::OrderEvent& event);
  // Runs `effect` at the end of this batch; with `after_publish` only once the snapshot
  // holding the batch's changes is published (replies, Welcomes, stream ends, robot messages
  // that come with an order change). Other plans, grants and holds need no snapshot and do
  // not force one.
  void Defer(std::function<void()> effect, bool after_publish = true) {
    effects_.Defer(std::move(effect), after_publish);
  }
  void CloseLink(const std::shared_ptr<RobotLink>& link, ServiceStatus status);

  // Allocation rounds (dispatcher_allocation.cpp): the core's round inputs, run by the
  // round worker, committed back a few awards per loop turn.
  void AllocatePending();
  void CommitNext(std::shared_ptr<ServerRound> round);

  // Robots (dispatcher_robots.cpp).
  void DoRobotMessage(const std::shared_ptr<RobotLink>& link, const RobotInbound& message);
  void DoHello(const std::shared_ptr<RobotLink>& link, const RobotInbound& hello);
  // A report's outcome: its order start stored, then the picks and drops that waited for it.
  void Progressed(const std::string& robot_id, engine::ReportOutcome outcome);
  void DoTaskEvent(const std::string& robot_id, const engine::TaskReport& report);
  // A report that was not plausible (engine/dispatch/report_check.h): logged and counted.
  void Implausible(const std::string& robot_id, const std::string& what, const std::string& why);
  void DoRobotGone(const std::shared_ptr<RobotLink>& link);
  void MarkOffline(const std::string& robot_id, const std::string& why);
  // The robot is lost (offline too long, blocked): its orders go back (core PlanLoss).
  bool LoseRobot(const std::string& robot_id, const std::string& why);
  // The wait after a restart is over: traffic control resumes (dispatcher_traffic.cpp).
  void EndRecoveryWait(bool timed_out);
  void Tick();
  void Publish();
  // Publishes the snapshot if anything changed, then runs the deferred effects.
  void Flush();

  // Traffic control (dispatcher_traffic.cpp).
  void StepTraffic();

  // Hands the batch's journal entries to the journal writer (if journaling).
  void WriteJournal() {
    if (journal_writer_) journal_writer_->Write(*core_);
  }

  const std::shared_ptr<const engine::WarehouseMap> map_;
  const std::shared_ptr<const engine::RouteTable> routes_;
  storage::Store& store_;
  const DispatcherOptions options_;
  WatchHub hub_;

  CommandQueue queue_;  // thread-safe
  std::thread thread_;
  std::atomic<bool> started_{false};

  std::shared_ptr<const Snapshot> snapshot_;  // atomic_load / atomic_store only

  // Loop-thread state (no lock: only the loop touches it after Start).
  std::unique_ptr<engine::JournaledCore> core_;  // the dispatch book and its rules, journaled
  DispatchClock clock_;
  OrderViews book_;  // every open order and the newest finished ones, as operators read them
  RobotSessions sessions_;  // every robot the core knows, and their streams
  // Streams opened that have sent nothing yet, with when they opened (OnRobotStreamOpened).
  std::map<std::shared_ptr<RobotLink>, Clock::time_point> awaiting_hello_;
  std::int64_t last_order_number_ = 0;
  std::uint64_t snapshot_version_ = 0;
  BatchEffects effects_;  // the batch's deferred effects; whether the snapshot is stale
  // Finished orders beyond finished_retained before Retire trims (one rebuild of the book's
  // indexes per this many finishes, not one per finish).
  static constexpr std::size_t kRetireSlack = 64;
  RoundSchedule rounds_due_;  // when the next allocation round runs
  DistanceWatch distances_;   // the closest two robots so far
  MemoryTrim memory_trim_;    // the threads' malloc arenas trimmed every 10 s
  RestartWait restart_wait_;  // see the top, "Restart"
  std::uint64_t implausible_ = 0;  // robot reports not taken (Implausible)
  // Route searches of new orders (SubmitOrder) and allocation rounds: off the loop thread.
  // Stopped first (Stop, destructor): what they still hold reaches the loop's queue.
  std::unique_ptr<WorkerThread> route_worker_;
  RoundWorker round_worker_;
  // Journal writes (options_.journal), in batch order; stopped last. Null: no journal.
  std::unique_ptr<CoreJournalWriter> journal_writer_;
};

}  // namespace dispatch::server
