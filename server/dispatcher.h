// Dispatcher: the one writer of the engine state (SPEC §4 "Concurrency").
//
// One loop thread owns the order book, the robots (pose, link, current plan) and the
// allocator. API threads never touch them: they post commands (Post) and get the answer
// through a callback run on the loop thread (gRPC reactors finish from it; REST waits on a
// future, see Call). The loop publishes an immutable Snapshot (atomic shared_ptr swap) that
// reads use without locks of the loop: after every batch whose replies, journal events,
// Welcomes or stream ends announce a change (they go out only after that publish: read-your-writes), and
// otherwise at most every 20 ms while robots report (positions, grants and holds are at most
// that stale in REST).
//
// Durability: an order is committed to the Store (InsertOrder) before SubmitOrder answers
// OK; a failed write is an error to the caller and leaves the in-memory state unchanged.
// Awards (order -> assigned + the allocation explanation as a journal entry + the robots'
// plans) are one store transaction. At start the dispatcher recovers orders, explanations,
// robots and assignments from the store.
//
// Allocation (dispatcher_allocation.cpp): a round of the strategy (auction or greedy) over
// the connected robots starts after every batch in which an order arrived, a robot connected
// or finished an order, or an order came back for re-allocation - and the previous round has
// been committed (one round at a time). The loop copies the round's inputs (the accepted
// orders, every available robot's point, plan and queue); a worker thread builds a fresh
// engine::FleetState from them with every robot at its point now, replays its remaining
// orders into its queue (ReplayQueue), then auctions the orders in (priority, created) order;
// back on the loop, the awards whose robots and orders have not changed meanwhile are
// committed, a few per loop turn and each group in one store transaction (a new order's
// waypoints appended to the robots' plans); the others stay `accepted` for the next round. So traffic control (grants, holds) never
// waits for an auction or its route searches. New orders' route searches run on another
// worker before the loop sees the order (SubmitOrder). Orders stay `accepted` while no robot
// (or fewer than 3 for a formation) is connected.
//
// Robots: Hello registers (snapping the pose to the nearest map point within
// Options::robot_snap_tolerance); waypoints are numbered over the robot's whole life
// (AssignmentRecord::released_up_to keeps the highest sequence ever issued). Traffic control
// (dispatcher_traffic.cpp, TrafficGate): plans are sent with only the waypoints at the
// robot's point released; after every batch the gate runs the TrafficController and its
// releases go out as Grants (Resume after a Hold), its waits as Holds with the reason, its
// detours as PlanUpdates; a robot blocked with no alternative loses its orders (assigned ones
// are re-allocated, in-progress ones fail) and is marked fault. Progress: a pick (waypoint reached or picked event) moves the order to
// in_progress, the drop of every team member completes it. A robot silent for
// heartbeat_timeout goes offline (stream closed); after offline_grace more its assigned
// orders go back to accepted and are re-allocated, and its in_progress orders fail (the load
// is on a robot that is gone).
//
// Restart: robots stored offline are placed in the gate at their stored points (obstacles
// until they reconnect). Robots the old process had on line may have driven on since their
// record was written, and may still be driving to the horizon it released: until every one
// of them has reconnected and sent a state report, or heartbeat_timeout has passed since the
// loop started, the gate releases nothing (a robot back first must not be given a point one
// still away stands on or drives into). Those still away then are placed at their stored
// points; /api/v1/status lists whom the wait is for (traffic.awaiting_reconnect).
//
// Thread safety: the public methods are thread-safe; everything else runs on the loop thread.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "engine/dispatch/allocation_round.h"
#include "engine/dispatch/dispatch_core.h"
#include "engine/dispatch/journaled_core.h"
#include "engine/dispatch/robot_progress.h"
#include "engine/fleet/order.h"
#include "engine/routing/route_table.h"
#include "engine/traffic/traffic_controller.h"
#include "engine/traffic/traffic_gate.h"
#include "server/core_journal_writer.h"
#include "server/metrics.h"
#include "server/order_views.h"
#include "server/robot_link.h"
#include "server/robot_sessions.h"
#include "server/service_status.h"
#include "server/snapshot.h"
#include "server/watch_hub.h"
#include "server/worker_thread.h"
#include "storage/journal_store.h"
#include "storage/store.h"

namespace dispatch::server {

struct DispatcherOptions {
  engine::AllocationConfig allocation;
  std::string strategy = "auction";  // auction | greedy
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

struct SubmitReply {
  ServiceStatus status;
  std::shared_ptr<const OrderView> order;
  bool created = false;
};

struct OrderReply {
  ServiceStatus status;
  std::shared_ptr<const OrderView> order;
};

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
  void SubmitOrder(engine::OrderRequest request, std::function<void(SubmitReply)> done);
  void CancelOrder(std::string order_id, std::string reason, std::function<void(OrderReply)> done);

  // --- Robot streams -----------------------------------------------------------------
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
  void Post(std::function<void()> fn);
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
  // An allocation round on its way into the store: the core's commit, and per award the
  // explanation as the journal keeps it.
  struct ServerRound {
    engine::RoundCommit commit;
    std::vector<AllocationRecord> records;
    std::vector<std::string> details;  // AllocationDetail(records[i]), made on the worker
  };

  Dispatcher(std::shared_ptr<const engine::WarehouseMap> map,
             std::shared_ptr<const engine::RouteTable> routes, storage::Store& store,
             DispatcherOptions options, std::unique_ptr<engine::RoundRunner> rounds,
             std::unique_ptr<engine::JournaledCore> core);
  engine::Status Recover();
  void Loop();
  double Now() const;

  // Orders (dispatcher_orders.cpp).
  void DoSubmit(const engine::OrderRequest& request, const std::function<void(SubmitReply)>& done);
  void DoCancel(const std::string& order_id, const std::string& reason,
                const std::function<void(OrderReply)>& done);
  std::string NextOrderId();

  // Carrying out the core's changes (dispatcher_commit.cpp). Commit stores `change` in one
  // transaction (journal, plans, the robots' reserved message sequences; with `round` the
  // awards' explanations), then applies it to the core and the order views and sends its
  // messages. False (and *status) when the store failed: nothing changed.
  bool Commit(const engine::Change& change, const ServerRound* round, ServiceStatus* status = nullptr);
  // The robot as stored: the core's robot and the session.
  storage::RobotRecord RecordOf(const std::string& robot_id) const;
  // Stamps the robot's next message sequence and the time, and sends if connected.
  void SendTo(const std::string& robot_id, RobotOutbound message);
  void Send(std::vector<engine::RobotCommand> commands);
  // Publishes a committed journal event to the watchers (deferred, see Defer).
  void Journal(const storage::OrderEvent& event);
  // Runs `effect` at the end of this batch; with `after_publish` only once the snapshot
  // holding the batch's changes is published: replies, journal events, Welcomes and stream
  // ends leave the loop only once the state they announce is readable. Robot plans, grants and
  // holds need no snapshot and do not force one (see Flush).
  void Defer(std::function<void()> effect, bool after_publish = true);
  void CloseLink(const std::shared_ptr<RobotLink>& link, ServiceStatus status);

  // Allocation rounds (dispatcher_allocation.cpp): the core's round inputs, run by the
  // RoundRunner on the allocation worker, committed back a few awards per loop turn.
  void AllocatePending();
  std::shared_ptr<ServerRound> RunRound(const engine::RoundInput& input);
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
  // The robot reported after a restart; the wait ends when nobody is awaited any more.
  void Reported(const std::string& robot_id);
  // The wait after a restart is over: traffic control resumes (dispatcher_traffic.cpp).
  void EndRecoveryWait(bool timed_out);
  std::string AwaitedList() const;  // "R3, R7": the robots the wait is for
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

  // Command queue: guarded by queue_mu_.
  std::mutex queue_mu_;
  std::condition_variable queue_cv_;
  std::deque<std::function<void()>> queue_;
  bool stopping_ = false;
  std::thread thread_;
  std::atomic<bool> started_{false};

  std::shared_ptr<const Snapshot> snapshot_;  // atomic_load / atomic_store only

  // Allocation worker state (only rounds on allocation_worker_ touch it).
  std::unique_ptr<engine::RoundRunner> rounds_;
  // Loop-thread state (no lock: only the loop touches it after Start).
  std::unique_ptr<engine::JournaledCore> core_;  // the dispatch book and its rules, journaled
  Clock::time_point wall_start_;
  double time_base_ = 0.0;  // dispatcher seconds at wall_start_
  OrderViews book_;  // every open order and the newest finished ones, as operators read them
  RobotSessions sessions_;  // every robot the core knows, and their streams
  std::int64_t last_order_number_ = 0;
  std::uint64_t snapshot_version_ = 0;
  bool dirty_ = true;
  std::vector<std::function<void()>> deferred_;  // effects of the current batch
  bool deferred_need_publish_ = false;            // one of them waits for the snapshot
  static constexpr std::chrono::milliseconds kPublishEvery{20};
  // Finished orders beyond finished_retained before Retire trims (one rebuild of the book's
  // indexes per this many finishes, not one per finish).
  static constexpr std::size_t kRetireSlack = 64;
  Clock::time_point last_publish_{};
  bool retry_allocation_ = false;  // a store failure left work for the next tick
  bool allocation_due_ = false;  // an allocation round runs at the end of this batch
  bool round_running_ = false;   // a round is on the worker or waits to be committed
  bool round_again_ = false;     // a round became due meanwhile
  engine::MinDistance min_distance_;
  Clock::time_point next_distance_sample_{};
  // Restart (see the top): robots on line before it that have not reported since, and when
  // the gate stops waiting for them.
  std::set<std::string> awaiting_reconnect_;
  Clock::time_point awaiting_until_{};
  std::uint64_t implausible_ = 0;  // robot reports not taken (Implausible)
  // Route searches of new orders (SubmitOrder) and allocation rounds: off the loop thread.
  // Stopped first (Stop, destructor): what they still hold reaches the loop's queue.
  std::unique_ptr<WorkerThread> route_worker_;
  std::unique_ptr<WorkerThread> allocation_worker_;
  // Journal writes (options_.journal), in batch order; stopped last. Null: no journal.
  std::unique_ptr<CoreJournalWriter> journal_writer_;
};

}  // namespace dispatch::server
