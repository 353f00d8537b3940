// DispatchCore: the dispatch book and its rules in one owner (issue 15 §1), driven by the
// service (server/dispatcher*.cpp) and the simulators alike.
//
// What it owns: the open orders (state, the robots serving them, the members that dropped, the
// metres driven for them), the robots (pose, state, current point, plan with the life-long
// waypoint numbering, progress), the TrafficGate, which orders an allocation round sees and
// which of its awards still hold when they come back, and the release of a lost, blocked or
// cancelled robot's orders. Finished orders leave the book (their owner keeps what it wants of
// them).
//
// How it is driven. Inputs are values with a dispatcher time `now`; nothing here reads a
// clock, a thread or a file. A decision that changes what is durable comes in two phases: a
// Plan* call returns a Change (the order transitions and journal notes, the plans to store and
// the messages they imply) without touching the book; the owner stores it (one transaction) and
// then calls Apply, which updates the book and the gate and returns the robot messages to send.
// A store failure is then simply not applying the change: the book stays as it was. What needs
// no store (reports, arrivals, grants, holds) changes the book directly and returns messages.
//
// Not thread-safe: one owner. Round inputs are copies (orders shared read-only), so a round may
// run on another thread while the owner goes on.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "engine/common/result.h"
#include "engine/dispatch/allocation_round.h"
#include "engine/dispatch/assignment.h"
#include "engine/dispatch/robot_commands.h"
#include "engine/dispatch/robot_message.h"
#include "engine/dispatch/robot_progress.h"
#include "engine/fleet/order.h"
#include "engine/fleet/robot.h"
#include "engine/map/warehouse_map.h"
#include "engine/routing/route_table.h"
#include "engine/traffic/traffic_gate.h"

namespace dispatch::engine {

// When the gate asks for robots' next points if a configuration does not say
// (TrafficControllerConfig::execution): at their planned departures with the rules planner; as
// soon as their work is done (kClaim) with the planned planners (time windows, conflict
// elimination), whose plans wait: measured 2026-12-06 on the Chu2024 streams with 20%
// formations, seeds 1-3, 599 of 600 orders completed instead of 586.
PlanExecution DefaultPlanExecution(PlannerKind planner);

struct CoreOptions {
  // Metres a reported pose may be from the waypoint or stop it claims (report_check.h).
  double robot_snap_tolerance = 1.0;
  // Waypoints released point by point through the TrafficGate; off: every waypoint is sent
  // released (no grants or holds).
  bool traffic_control = true;
  TrafficControllerConfig traffic;
  // A formation order is allocated only while no other formation is still heading for its
  // first pick (MakeRound). Off (the engine's default): Chu2024 as printed, every order
  // awarded at once; dispatchd and dispatch-sim turn it on by default.
  bool one_formation_per_pick = false;
  // Seconds a robot the traffic controller found blocked stays in fault (an obstacle where it
  // stands, out of every auction) before it is back in service (idle, allocatable again; the
  // controller may block it again). A block is a traffic verdict, not a fault of the robot: it
  // still reports and drives. 0: it stays in fault until it says Hello again.
  double blocked_recovery = 60.0;
  // Times in a row an order may go back to accepted from the same robot lost at the same
  // point (PlanLoss: blocked, offline, out of service); the next such loss fails it, saying
  // why. A jam the controller cannot clear would otherwise hand the order back to the robot
  // nearest to it, which blocks there again, for ever (found on the Chu2024 burst through the
  // service). Losses elsewhere do not count: on the dense grids orders given back a dozen
  // times by different robots still complete. 0: no limit.
  int max_give_backs = 3;
};

// An open order as the core dispatches it.
struct BookOrder {
  std::shared_ptr<const Order> order;  // order->state is its state; replaced, never mutated
  std::vector<std::string> robots;     // serving it, leader first; empty while accepted
  std::set<std::string> dropped_by;    // team members that reported the drop
  double distance = 0.0;               // metres driven for it so far
  std::string lost_at;                 // "robot@point" of its last loss (PlanLoss)
  int lost_there = 0;                  // losses in a row with that key
};

struct BookRobot {
  Robot robot;  // pose, state, current point, task_queue (= assignment.order_ids)
  bool connected = false;
  bool has_assignment = false;
  Assignment assignment;  // plan.waypoints[0] anchors; then one segment per order
  // `assignment` as the last allocation round took it (MakeRound shares it with every round
  // until the plan changes, instead of copying the plan each round); every write to
  // `assignment` resets it.
  mutable std::shared_ptr<const Assignment> round_copy;
  RobotProgress progress;
  double blocked_at = -1.0;  // >= 0: in fault since then because the controller blocked it
  GateBot* gate_entry = nullptr;  // its entry in the traffic gate, once it has one (GateEntry)
  OperatorMarks marks;            // operator commands in force (PlanCommand)
};

// One order's line in a Change: a state transition (to) or a journal note only.
struct OrderChange {
  std::string order_id;
  std::optional<OrderState> to;                   // nullopt: a note (progress), no transition
  std::optional<std::vector<std::string>> robots;  // serving it after the change; nullopt keeps
  std::string detail;                              // journaled; the reason when cancelled/failed
  std::optional<double> distance;                  // completed: metres driven for it
  std::size_t award = kNoAward;                    // assigned: index into the round's awards
  std::string lost_at;                             // accepted by PlanLoss: "robot@point" lost at
  static constexpr std::size_t kNoAward = static_cast<std::size_t>(-1);
};

// A plan message a Change implies once applied (made then: what is released depends on it).
struct PlanSend {
  enum class Kind { kFull, kUpdate, kCancel };
  std::string robot;
  Kind kind = Kind::kFull;
  std::uint64_t from_sequence = 0;     // kUpdate
  std::vector<std::string> cancelled;  // kCancel
  std::string reason;                  // kCancel
};

struct Change {
  double time = 0.0;
  std::vector<OrderChange> orders;          // in journal order
  std::map<std::string, Assignment> plans;  // robot -> its new plan (stored whole)
  std::vector<PlanSend> sends;
  std::map<std::string, std::set<std::string>> dropped_by;  // order -> members that dropped now
  std::uint64_t origin = 0;  // the journal entry of the call that made it (JournaledCore); 0: none
  std::map<std::string, OperatorMarks> marks;  // robot -> its operator marks after the change
  bool empty() const {
    return orders.empty() && plans.empty() && sends.empty() && dropped_by.empty() && marks.empty();
  }
  // Messages per robot once applied (the owner reserves their sequence numbers with the change).
  std::map<std::string, std::uint64_t> MessageCounts() const;
};

// A message for a robot.
struct RobotCommand {
  std::string robot;
  RobotMessage message;
};

// What must not have changed for an award computed on a round's copy to be committed.
struct RoundKey {
  std::uint64_t plan_id = 0;
  std::string last_order;  // the queue's last order ("": none)
  PointId start = kNoPoint;
  bool operator==(const RoundKey& o) const {
    return plan_id == o.plan_id && last_order == o.last_order && start == o.start;
  }
};

// A round on its way back into the book, a few awards at a time (PlanAwards).
struct RoundCommit {
  std::uint64_t origin = 0;  // the journal entry of its MakeRound (JournaledCore); 0: none
  std::map<std::string, RoundKey> keys;  // as the round saw them; then as committed
  std::vector<RoundAward> awards;
  std::size_t next = 0;            // the first award not looked at yet
  std::set<std::string> spoiled;   // robots the round may not change any more
  bool again = false;              // an award did not hold: another round is due
};

// A waypoint arrival or a state report.
struct ReportOutcome {
  bool taken = true;
  std::string why;                  // not taken: what was implausible
  std::optional<Change> change;     // an order started (a pick reached): store, then Apply
  std::vector<TaskReport> retry;    // picks and drops that waited for this progress: PlanTask each
};

// A pick or drop report.
struct TaskOutcome {
  enum class Kind { kIgnored, kWaiting, kImplausible, kChange };
  Kind kind = Kind::kIgnored;  // kIgnored: late, repeated or not this robot's order
  std::string what;            // "dropped for order X" (kWaiting, kImplausible)
  std::string why;             // kWaiting, kImplausible
  bool overflowed = false;     // kWaiting: an older waiting report was dropped for it
  Change change;               // kChange
};

struct StepOutcome {
  std::vector<RobotCommand> messages;  // Grants, Holds, Resumes, PlanUpdates (re-plans), in order
  std::vector<Assignment> rewritten;   // re-planned legs: the owner stores them (best effort)
  // Robots the controller found blocked with no alternative, with why: now in fault; the owner
  // gives their orders back (PlanLoss).
  std::vector<std::pair<std::string, std::string>> blocked;
  // Robots blocked for CoreOptions::blocked_recovery with no orders left: idle again.
  std::vector<std::string> recovered;
  std::vector<std::string> notes;  // formations formed, broken up, leaving (for the owner's log)
};

struct CoreCounts {
  std::uint64_t grants = 0, holds = 0, replans = 0;
};

// One waypoint of an order's remaining route (for operators).
struct RouteWaypoint {
  std::uint64_t seq = 0;
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();
  WaypointAction action = WaypointAction::kMove;
  bool released = false;
  std::optional<double> heading;   // a four-wheel-steer robot's pose in a free space (Waypoint)
  std::optional<MotionMode> mode;
};
using OrderRoutes = std::map<std::string, std::vector<RouteWaypoint>>;  // by robot id

class DispatchCore {
 public:
  // Errors: null map or routes, a bad traffic configuration.
  static Result<std::unique_ptr<DispatchCore>> Create(std::shared_ptr<const WarehouseMap> map,
                                                      std::shared_ptr<const RouteTable> routes,
                                                      CoreOptions options);
  DispatchCore(const DispatchCore&) = delete;
  DispatchCore& operator=(const DispatchCore&) = delete;

  // --- The book (read) -------------------------------------------------------------------
  const BookOrder* order(const std::string& id) const;
  const BookRobot* robot(const std::string& id) const;
  const std::map<std::string, BookRobot>& robots() const { return robots_; }
  const std::map<std::string, BookOrder>& orders() const { return orders_; }
  const TrafficGate* gate() const { return gate_.get(); }  // null without traffic control
  const CoreCounts& counts() const { return counts_; }
  // Highest waypoint sequence released to the robot.
  std::uint64_t ReleasedUpTo(const std::string& robot) const;
  // The station point an operator sent the robot to, while it drives there; kNoPoint otherwise.
  PointId TripTo(const std::string& robot) const;
  // The waypoints of `order_id` its robots have not reached yet.
  OrderRoutes RoutesOf(const std::string& order_id) const;
  // True once since the last call when something happened that a new allocation round may
  // use (an order arrived or came back, a robot connected or finished an order).
  bool TakeAllocationDue();

  // --- Orders ----------------------------------------------------------------------------
  // An admitted order (engine/dispatch/order_intake.h), stored by the owner; recovery passes
  // the robots an assigned or started order has. Terminal orders are not taken.
  void AddOrder(Order order, std::vector<std::string> robots = {});
  // Cancels an open order (kNotFound when it is not in the book). Orders queued after it on
  // its robots go back to accepted.
  Result<Change> PlanCancel(const std::string& order_id, const std::string& reason, double now);
  // Gives back every order of a lost or blocked robot (started ones fail, the others are
  // re-allocated, engine::StateAfterRobotLoss; one lost by this robot at this point
  // CoreOptions::max_give_backs times in a row already fails). Empty when it has none.
  Change PlanLoss(const std::string& robot, const std::string& why, double now);

  // --- Allocation rounds -----------------------------------------------------------------
  // A round over the accepted orders and the eligible robots (connected, on a point, not in
  // fault, not waiting in a finished formation's slot); nullopt when either is missing.
  // `commit` receives the robots' keys.
  std::optional<RoundInput> MakeRound(double now, RoundCommit& commit) const;
  // The commit of the round's next `max` awards: those whose orders are still accepted and
  // whose robots still have the keys the round saw (the others set commit.again).
  Change PlanAwards(RoundCommit& commit, std::size_t max, double now) const;
  // After a stored and applied PlanAwards change: the round's later awards build on these plans.
  void Committed(RoundCommit& commit, const Change& change) const;

  // --- Robots ----------------------------------------------------------------------------
  // Recovery: a robot as stored (offline until it reconnects) with its plan and the operator
  // marks in force; `place` puts it in the gate at its stored point as an obstacle (Place).
  void RestoreRobot(Robot robot, std::optional<Assignment> plan, bool place, OperatorMarks marks = {});
  // Puts a robot that is not connected in the gate at its point (an obstacle there), unless an
  // operator cleared it off the floor.
  void Place(const std::string& robot);
  // A checked Hello (robot_intake.h): the robot stands at robot.current_point. Returns its
  // current plan again when it has orders (it skips waypoints it has passed).
  std::vector<RobotCommand> Connect(Robot robot, double now);
  // Its stream is gone: offline, still an obstacle where it was.
  void Disconnect(const std::string& robot);
  // A state report. A pose off the floor is no news (nothing changes); the state is taken
  // unless the robot is in fault; `claimed` is its last waypoint passed (taken up to the highest
  // ever numbered).
  ReportOutcome Report(const std::string& robot, const Pose& pose, std::optional<int> arc_id,
                       std::optional<RobotState> state, std::optional<double> battery,
                       std::uint64_t claimed, double now);
  // "Reached waypoint seq" (with the pose it sent, if any).
  ReportOutcome Reached(const std::string& robot, std::uint64_t seq, const std::optional<Pose>& pose,
                        double now);
  // "Picked" / "dropped": a pick starts the order, every member's drop completes it.
  TaskOutcome PlanTask(const std::string& robot, const TaskReport& report, double now);
  // An operator's command on a robot (robot_commands.h); the change carries the robot's new
  // marks (Change::marks), which the owner stores with the robot. Applied:
  // - pause / resume: held at its next point by the gate (TrafficGate::SetPaused) / released
  //   again; plan and orders stay. A robot out of service stays held when resumed.
  // - out_of_service: its orders given back as for a lost robot (started ones fail, the others
  //   are re-allocated), held where it stands; return_to_service: released, allocatable again.
  // - clear: a robot that is not connected is taken off the floor (TrafficGate::Remove: no
  //   obstacle for the others), its orders given back, until it says Hello again.
  // - send: an idle robot (connected, in service, not paused, in fault, or serving orders)
  //   drives its route to point `to` (a park or charge waypoint at the end); it bids for
  //   nothing until it has reached it. Not to a point another robot stands at or is sent to.
  // Paused, out-of-service and robots on their way to a station are not Eligible; robots
  // paused or out of service stay so across reconnects. Errors: unknown robot (kNotFound); no
  // traffic control for pause (kFailedPrecondition: nothing to hold with); clear of a connected
  // robot, send of a busy robot or to a taken point (kFailedPrecondition); no route
  // (kUnreachable); an unknown point (kNotFound).
  Result<Change> PlanCommand(const OperatorCommand& command, double now);

  // --- Applying and traffic --------------------------------------------------------------
  // Applies a stored Change: order states, plans, the gate; returns the plan messages.
  std::vector<RobotCommand> Apply(const Change& change);
  // Runs the traffic controller (no-op without traffic control) and puts robots blocked for
  // CoreOptions::blocked_recovery back in service.
  StepOutcome Step(double now);
  // Updates the gate's minimum distance from the robots' last positions.
  void SampleDistances(double now);

 private:
  DispatchCore(std::shared_ptr<const WarehouseMap> map, std::shared_ptr<const RouteTable> routes,
               CoreOptions options);
  BookRobot* FindRobot(const std::string& id);
  BookRobot& Book(const std::string& id);  // the robot's entry, made (and indexed) if new
  bool Eligible(const BookRobot& r) const;
  // On its way to a station an operator sent it to (its order-less plan ends at a park or
  // charge waypoint it has not reached).
  bool OnTrip(const BookRobot& r) const;
  Result<Change> PlanTrip(const BookRobot& r, PointId to, double now) const;
  PointId StartOf(const BookRobot& r) const;
  RoundKey KeyOf(const BookRobot& r) const;
  // r's entry in the gate (nullptr: none yet), looked up by id until it has one.
  GateBot* GateEntry(BookRobot& r, const std::string& id);
  // Releases `order_ids` (targets by PlanRelease) with `reason`.
  Change PlanReleaseOf(const std::vector<std::string>& order_ids,
                       const std::function<OrderState(OrderState)>& target, const std::string& reason,
                       double now) const;
  // The order start (assigned -> in_progress) as one change line; nullopt when not assigned.
  std::optional<OrderChange> StartLine(const std::string& order_id, const std::string& detail) const;
  GatePlan GatePlanOf(const BookRobot& r) const;
  void SyncGate(const BookRobot& r);
  RobotMessage PlanMessage(const BookRobot& r, bool full, std::uint64_t from_sequence) const;
  void ApplyOrder(const OrderChange& line);
  void Recover(double now, StepOutcome& out);

  const std::shared_ptr<const WarehouseMap> map_;
  const std::shared_ptr<const RouteTable> routes_;
  const CoreOptions options_;
  std::unique_ptr<TrafficGate> gate_;  // null without traffic control
  std::map<std::string, BookOrder> orders_;
  std::map<std::string, BookRobot> robots_;  // never erased: robot_index_ points into it
  // robots_ by id in one hash lookup (every report and arrival looks its robot up).
  std::unordered_map<std::string, BookRobot*> robot_index_;
  // robots_ in bidding order (NaturalLess of their ids, the map's keys), kept as they are
  // booked: every round bids them in this order.
  std::vector<std::pair<const std::string*, BookRobot*>> bidding_order_;
  CoreCounts counts_;
  std::vector<BookRobot*> blocked_;  // in fault since the controller blocked them
  bool allocation_due_ = false;
  std::uint64_t leaving_seen_ = 0;  // the gate's LeavingEnded() when last stepped
};

}  // namespace dispatch::engine
