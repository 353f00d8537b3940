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
#include "engine/dispatch/robot_progress.h"
#include "engine/fleet/order.h"
#include "engine/routing/route_table.h"
#include "engine/traffic/traffic_controller.h"
#include "engine/traffic/traffic_gate.h"
#include "server/metrics.h"
#include "server/robot_link.h"
#include "server/service_status.h"
#include "server/snapshot.h"
#include "server/watch_hub.h"
#include "server/worker_thread.h"
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
  // Where allocation latency and grant waits are observed (optional; must outlive the
  // dispatcher).
  ServiceMetrics* metrics = nullptr;
};

struct SubmitReply {
  ServiceStatus status;
  std::shared_ptr<const OrderView> order;
  bool created = false;
};

struct OrderReply {
  ServiceStatus status;
  std::shared_ptr<const OrderView> order;
};

// One waypoint of an order's remaining route (for operators: GET /api/v1/orders/{id}).
struct RouteWaypoint {
  std::uint64_t seq = 0;
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();
  engine::WaypointAction action = engine::WaypointAction::kMove;
  bool released = false;
};
using OrderRoutes = std::map<std::string, std::vector<RouteWaypoint>>;  // by robot id

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
  using Clock = std::chrono::steady_clock;
  struct RobotRuntime {
    storage::RobotRecord record;
    std::shared_ptr<RobotLink> link;  // null when not connected
    Clock::time_point last_heard;
    std::optional<Clock::time_point> offline_since;  // set while offline with orders to watch
    storage::AssignmentRecord assignment;  // plan.waypoints[0] anchors; then one segment per order
    bool has_assignment = false;
    // What it reported reaching, where, and its picks and drops waiting for its progress.
    engine::RobotProgress progress;
    std::optional<double> held_since;  // dispatcher seconds of the Hold in force
  };

  Dispatcher(std::shared_ptr<const engine::WarehouseMap> map,
             std::shared_ptr<const engine::RouteTable> routes, storage::Store& store,
             DispatcherOptions options, std::unique_ptr<engine::RoundRunner> rounds);
  engine::Status Recover();
  void Loop();
  double Now() const;

  // Orders (dispatcher.cpp).
  void DoSubmit(const engine::OrderRequest& request, const std::function<void(SubmitReply)>& done);
  void DoCancel(const std::string& order_id, const std::string& reason,
                const std::function<void(OrderReply)>& done);
  std::shared_ptr<const OrderView> Find(const std::string& order_id) const;
  // Replaces (or adds, at the end) an order in the book; a finished one joins the finished
  // list that Retire trims.
  void Put(std::shared_ptr<OrderView> view);
  // Once more than finished_retained + slack finished orders are in memory, the oldest
  // finished ones leave it (they stay in the store) down to finished_retained.
  void Retire(std::size_t slack);
  // Publishes a committed journal event to the watchers (deferred, see Defer).
  void Journal(const storage::OrderEvent& event);
  // Runs `effect` at the end of this batch; with `after_publish` only once the snapshot
  // holding the batch's changes is published: replies, journal events, Welcomes and stream
  // ends leave the loop only once the state they announce is readable. Robot plans, grants and
  // holds need no snapshot and do not force one (see Flush).
  void Defer(std::function<void()> effect, bool after_publish = true);
  void CloseLink(const std::shared_ptr<RobotLink>& link, ServiceStatus status);
  std::string NextOrderId();

  // Allocation rounds (dispatcher_allocation.cpp): the core's RoundRunner on the allocation
  // worker, from a copy of its inputs made on the loop thread.
  // What must not have changed for an award computed on the copy to be committed.
  struct RoundKey {
    std::uint64_t plan_id = 0;
    std::string last_order;  // the queue's last order ("": none)
    engine::PointId start = engine::kNoPoint;
    bool operator==(const RoundKey& o) const {
      return plan_id == o.plan_id && last_order == o.last_order && start == o.start;
    }
  };
  struct RoundAward {
    engine::RoundAward plan;  // segments per winner (its award moved into record)
    AllocationRecord record;  // the award and the weights it was made with
    std::string detail;       // the explanation as stored (AllocationDetail), made on the worker
  };
  // A round's awards on their way into the store, kCommitChunk per loop turn.
  struct RoundCommit {
    std::map<std::string, RoundKey> keys;  // as the round saw them; then as committed
    std::vector<RoundAward> awards;
    std::size_t next = 0;                  // the first award not looked at yet
    std::set<std::string> spoiled;         // robots the round may not change any more
  };
  // Loop: starts a round on the allocation worker (or marks one due after the running one).
  void AllocatePending();
  // Loop: whether a round may use the robot; where a new plan of it would start; its key.
  bool Eligible(const RobotRuntime& robot) const;
  engine::PointId StartOf(const RobotRuntime& robot) const;
  RoundKey KeyOf(const RobotRuntime& robot) const;
  // Worker: the round's awards.
  std::vector<RoundAward> RunRound(const engine::RoundInput& input);
  // Loop: commits the round's next kCommitChunk awards, in one store transaction: those whose
  // orders are still accepted and whose robots are still eligible with the keys the round saw;
  // marks another round due when some were not. False if the store failed (nothing of this
  // chunk changed).
  bool CommitRound(RoundCommit& commit);
  // Loop: CommitRound, then the rest of the round in a later loop turn (robots are served in
  // between), then the end of the round.
  void CommitNext(std::shared_ptr<RoundCommit> commit);
  // Takes `order_ids` away from their robots and moves each to target(order) (cancelled,
  // failed, or accepted for re-allocation) with `reason`; orders queued after them on the
  // same robots go back to accepted. One store transaction; false (and *status) on failure,
  // with nothing changed.
  bool ReleaseOrders(const std::vector<std::string>& order_ids,
                     const std::function<engine::OrderState(const OrderView&)>& target,
                     const std::string& reason, ServiceStatus* status);
  // Assignment (full plan) or PlanUpdate (waypoints from `from_sequence` on).
  RobotOutbound PlanMessage(const RobotRuntime& robot, bool full, std::uint64_t from_sequence) const;
  // Stamps the robot's next message sequence and the time, and sends if connected.
  void SendTo(RobotRuntime& robot, RobotOutbound message);
  RobotRuntime* RobotOf(const std::string& id);

  // Robots (dispatcher_robots.cpp).
  void DoRobotMessage(const std::shared_ptr<RobotLink>& link, const RobotInbound& message);
  void DoHello(const std::shared_ptr<RobotLink>& link, const RobotInbound& hello);
  void DoWaypointReached(RobotRuntime& robot, const RobotInbound& message);
  void DoTaskEvent(RobotRuntime& robot, const engine::TaskReport& report);
  // Runs the robot's waiting picks and drops again (it reported progress).
  void RetryTaskEvents(RobotRuntime& robot, std::vector<engine::TaskReport> waiting);
  // A report that was not plausible (engine/dispatch/report_check.h): logged and counted.
  void Implausible(RobotRuntime& robot, const std::string& what, const std::string& why);
  void DoRobotGone(const std::shared_ptr<RobotLink>& link);
  void MarkOffline(RobotRuntime& robot, const std::string& why);
  // Places a robot that is not connected in the gate at its stored point (an obstacle).
  void PlaceAway(const RobotRuntime& robot);
  // The robot reported after a restart; the wait ends when nobody is awaited any more.
  void Reported(const std::string& robot_id);
  // The wait after a restart is over: traffic control resumes (dispatcher_traffic.cpp).
  void EndRecoveryWait(bool timed_out);
  std::string AwaitedList() const;  // "R3, R7": the robots the wait is for
  void StartOrder(const std::string& order_id, const std::string& detail);
  void Tick();
  void Publish();
  // Publishes the snapshot if anything changed, then runs the deferred effects.
  void Flush();
  // Live zone densities from the robots' reported positions (their current point's zone).
  std::vector<ZoneView> ZoneViews(const std::map<std::string, RobotView>& robots) const;

  // Traffic control (dispatcher_traffic.cpp).
  engine::GatePlan GatePlanOf(const RobotRuntime& robot) const;
  void SyncGate(const RobotRuntime& robot);  // tells the gate the robot's current plan
  void StepTraffic();
  void ApplyGateEffect(engine::GateEffect& effect);
  std::uint64_t ReleasedUpTo(const RobotRuntime& robot) const;

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
  std::unique_ptr<engine::TrafficGate> gate_;  // null when traffic control is off
  Clock::time_point wall_start_;
  double time_base_ = 0.0;  // dispatcher seconds at wall_start_
  // The book: every open order and the newest finished ones, by position (submission order).
  std::vector<std::shared_ptr<const OrderView>> orders_;
  std::unordered_map<std::string, std::size_t> by_id_;
  std::unordered_map<std::string, std::size_t> by_client_id_;
  std::deque<std::string> finished_;  // the finished orders in memory, in finish order
  std::map<engine::OrderState, std::uint64_t> finished_in_store_;  // retired, by state
  std::uint64_t book_generation_ = 0;  // changes when orders join or leave the book
  std::uint64_t published_generation_ = 0;
  std::shared_ptr<const Snapshot::OrderIndex> published_index_;  // copy of the two maps above
  std::map<std::string, RobotRuntime> robots_;
  std::unordered_map<const RobotLink*, std::string> link_robot_;
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
  bool retry_allocation_ = false;
  bool allocation_due_ = false;  // an allocation round runs at the end of this batch
  bool round_running_ = false;   // a round is on the worker or waits to be committed
  bool round_again_ = false;     // a round became due meanwhile
  engine::MinDistance min_distance_;
  std::unordered_map<std::string, double> order_distance_;  // metres driven, open orders
  Clock::time_point next_distance_sample_{};
  // Restart (see the top): robots on line before it that have not reported since, and when
  // the gate stops waiting for them.
  std::set<std::string> awaiting_reconnect_;
  Clock::time_point awaiting_until_{};
  struct {
    std::uint64_t grants = 0, holds = 0, replans = 0;
    std::uint64_t implausible = 0;  // robot reports not taken (Implausible)
  } traffic_counts_;
  // Route searches of new orders (SubmitOrder) and allocation rounds: off the loop thread.
  // Stopped first (Stop, destructor): what they still hold reaches the loop's queue.
  std::unique_ptr<WorkerThread> route_worker_;
  std::unique_ptr<WorkerThread> allocation_worker_;
};

}  // namespace dispatch::server
