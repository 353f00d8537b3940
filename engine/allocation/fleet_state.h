// FleetState: the allocator's view of the fleet (SPEC §3.2, Chu2024 §2.2 "each robot has a
// sequence of assigned tasks, updated after every round").
//
// Per robot (in the order added, which is the auction's tie-break order): its id, start point
// and ready time, the queue of awarded tasks, its timed Plan (SPEC §3.4) and a summary of the
// queue for O(1) bids: where and when the queue ends, and its accumulated travel time T_d
// (sum of route-table costs between consecutive stops, i.e. Floyd distances / v) and work
// time T_w (n_c * t_w + drop time per task, Chu2024 eq. (3)). The TrafficPredictor holds every robot's
// current plan followed by a wait of AllocationConfig::hold_seconds where it ends (so idle,
// parked and finished robots still count; an idle robot's plan is its start waypoint).
//
// Tasks are only ever appended (Restore and Reset replace a robot's whole entry). A single
// task's plan segment is BuildPlan from the queue's end point and end time. A formation task
// (Chu2024 §3.2) is BuildFormationPlans for its three members, where each member's leg to the
// first pick starts when that member has finished its own earlier queue, and the formation
// departs when the last member is in its slot (T_r); members wait in their slots until then
// (that wait is in the plan's times, not in T_d/T_w).
//
// Invariants: every plan is the concatenation of its queue's segments, so a robot never has
// two overlapping pieces of work (etas non-decreasing along the plan); summaries and the
// predictor match the plans after every Assign*. An Assign* that fails changes nothing.
// Not thread-safe: one allocator mutates a FleetState at a time. Move-only (the predictor is
// not meant to be shared between copies).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "engine/allocation/allocation_config.h"
#include "engine/allocation/traffic_prediction.h"
#include "engine/common/result.h"
#include "engine/fleet/plan.h"
#include "engine/fleet/robot.h"
#include "engine/map/warehouse_map.h"
#include "engine/motion/free_space_plan.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine {

struct FleetRobot {
  std::string id;
  PointId start = kNoPoint;
  double ready_time = 0.0;  // seconds; when the robot can start its first task
  RobotKind kind = RobotKind::kDifferential;
};

struct QueuedTask {
  std::string order_id;
  PlanTask task;
  std::vector<std::string> team;  // formation: the 3 members, leader first; single: {robot}
  double start_time = 0.0;        // when the robot leaves for this task
  double end_time = 0.0;          // departure from the drop (after its work)
};

struct QueueSummary {
  PointId end_point = kNoPoint;  // where the queue ends (start point if empty)
  double end_time = 0.0;         // when it ends (ready time if empty)
  double travel_time = 0.0;      // T_d of the queue so far, s
  double work_time = 0.0;        // T_w of the queue so far, s
};

class FleetState {
 public:
  // Errors (kInvalidArgument / kNotFound) name the robot or field: bad config, null map or
  // routes, empty or duplicate robot ids, unknown start points, non-finite ready times, a
  // zone index with another zone count or cell size. `zones`: the predictor's ZoneIndex,
  // built for this map (a previous state's zone_index(), so a state rebuilt every round
  // does not re-grid the floor); null builds one. With publish = false the predictor sees
  // no robot until Publish(robot) (a caller that gives most robots a queue first: their start
  // alone would be predicted for hold_seconds, then taken back).
  static Result<FleetState> Create(std::shared_ptr<const WarehouseMap> map,
                                   std::shared_ptr<const RouteTable> routes,
                                   const std::vector<FleetRobot>& robots,
                                   const AllocationConfig& config = {},
                                   std::shared_ptr<const ZoneIndex> zones = nullptr, bool publish = true);

  FleetState(FleetState&&) = default;
  FleetState& operator=(FleetState&&) = default;
  FleetState(const FleetState&) = delete;
  FleetState& operator=(const FleetState&) = delete;

  std::size_t robot_count() const { return robots_.size(); }
  const std::string& robot_id(std::size_t robot) const { return robots_.at(robot).info.id; }
  std::optional<std::size_t> FindRobot(const std::string& id) const;
  const FleetRobot& robot(std::size_t robot) const { return robots_.at(robot).info; }
  const QueueSummary& summary(std::size_t robot) const { return robots_.at(robot).summary; }
  const std::vector<QueuedTask>& queue(std::size_t robot) const { return robots_.at(robot).queue; }
  // False when the robot's queue holds AllocationConfig::max_queue orders, or for a formation
  // order formation_max_queue: it does not bid.
  bool HasRoom(std::size_t robot, bool formation = false) const {
    const std::size_t held = queue(robot).size();
    if (config().max_queue != 0 && held >= config().max_queue) return false;
    return !formation || config().formation_max_queue == 0 || held < config().formation_max_queue;
  }
  // False when `task` asks for a heading at a stop (PlanTask::stop_headings) and the robot
  // cannot be planned into it: it is not a four-wheel-steer robot, or no free-space motion is
  // in use (UseFreeSpace). Such a robot does not bid for it (every strategy asks).
  bool CanServe(std::size_t robot, const PlanTask& task) const {
    return task.stop_headings.empty() ||
           (free_space_ != nullptr && robots_.at(robot).info.kind == RobotKind::kFourWheelSteer);
  }
  const Plan& plan(std::size_t robot) const { return robots_.at(robot).plan; }

  const WarehouseMap& map() const { return *map_; }
  const RouteTable& routes() const { return *routes_; }
  // From now on plans and costs (bids) use `routes` (a round's heat-weighted table); the plans
  // made so far stay as they are. kInvalidArgument for null or a table of another map size.
  Status UseRoutes(std::shared_ptr<const RouteTable> routes);
  const AllocationConfig& config() const { return config_; }
  const TrafficPredictor& predictor() const { return *predictor_; }
  const std::shared_ptr<const ZoneIndex>& zone_index() const { return predictor_->zone_index(); }
  // Robot `robot`'s plan in the predictor (predictor().Find(robot_id(robot)) without the lookup).
  TrafficPredictor::PlanHandle prediction(std::size_t robot) const {
    return robots_.at(robot).prediction;
  }

  // The PlanTask of an order under this config (t_w = override or the order's own).
  PlanTask TaskOf(const std::vector<PointId>& picks, PointId drop, double order_work_time) const;
  // Table cost of serving `task` once at its first pick: pick -> pick ... -> drop, seconds
  // (+infinity if some leg is unreachable).
  double TaskTravelTime(const PlanTask& task) const;

  // Appends `task` to robot's queue and plan. Errors: unknown robot index, unreachable legs.
  Status AssignSingle(std::size_t robot, const std::string& order_id, const PlanTask& task);
  // The same with the task's waypoints already planned (a queue replayed from stored plans:
  // no routing). segment[0] stands for the queue's end point; the segment is shifted to start
  // at the queue's end time, and its driving time (arrivals minus the previous departures)
  // counts as the task's T_d. Errors: unknown robot index, fewer than 2 waypoints, times
  // that go backwards, a last waypoint that is not the task's drop. With publish = false the
  // traffic predictor does not see the new plan until Publish(robot) (a queue of several
  // orders replayed at once is predicted once, not once per order); until then the robot's
  // prediction is its plan before the call.
  Status AssignPlanned(std::size_t robot, const std::string& order_id, const PlanTask& task,
                       std::vector<Waypoint> segment, bool publish = true);
  // Gives the predictor robot's current plan (after AssignPlanned with publish = false).
  void Publish(std::size_t robot) { Publish(robots_.at(robot)); }

  // One robot's queue, plan and summary as a value, with the ready time they were made from
  // and the prediction's trace (TrafficPredictor::Trace of the plan and its hold on buckets
  // from that ready time): for a caller that keeps a fleet from round to round and a robot's
  // replayed queue while it stays the same (RoundRunner), moved to each round's ready time.
  struct RobotSnapshot {
    std::vector<QueuedTask> queue;
    Plan plan;
    QueueSummary summary;
    double ready_time = 0.0;
    TrafficPredictor::Contribution trace;
  };
  RobotSnapshot Snapshot(std::size_t robot) const;
  // The prediction's trace of robot's plan and hold on buckets from its ready time.
  TrafficPredictor::Contribution Trace(std::size_t robot) const;
  // Moves robot's entry to the predictor's bucket start `bucket` (every time + that start -
  // its ready time) and predicts it from `trace` (its Trace() taken before the move; null:
  // traced here) moved `bucket` buckets: Restore of its own Snapshot without the copies.
  // Errors: an unknown index.
  Status Settle(std::size_t robot, std::size_t bucket, const TrafficPredictor::Contribution* trace = nullptr);
  // Replaces robot's start, ready time, queue, plan and summary with the snapshot's, moved to
  // the predictor's bucket start `bucket` (every time + that start - snapshot.ready_time), and
  // its prediction with the trace moved `bucket` buckets (no Publish needed). Reuses the
  // entry's buffers. Errors (nothing changed): an unknown index, a snapshot of another robot
  // or of no plan (kInvalidArgument).
  Status Restore(std::size_t robot, const RobotSnapshot& snapshot, std::size_t bucket);
  // Robot back to no queue, standing at `start` from `ready_time`, as Create makes it; its
  // prediction is unchanged until Publish. Errors: an unknown index or start point, a
  // non-finite ready time.
  Status Reset(std::size_t robot, PointId start, double ready_time);
  // Moves on at every change of robot's entry or its prediction (Assign*, Publish, Restore,
  // Reset): a caller that keeps a fleet between rounds knows which robots a round changed.
  std::uint64_t revision(std::size_t robot) const { return robots_.at(robot).revision; }
  // Appends a formation task to the three distinct members' queues (team[0] leads).
  Status AssignFormation(const std::array<std::size_t, 3>& team, const std::string& order_id,
                         const PlanTask& task);

  // From now on AssignSingle plans a four-wheel-steer robot's segment through the map's
  // free-space regions (FreeSpaceMotion::Refine, with the task's stop headings, else the
  // graph's headings at its stops); null: on the lanes, as every robot. A segment the hybrid
  // A* cannot refine (an anchor pose that does not fit the region, no path, the search limits)
  // keeps its lanes, unless its task asks for a heading: then AssignSingle fails saying why.
  // Every strategy prices the refined legs (RefinedExtra): the auction's bids, the exact
  // assignment's costs and the greedy rule's distance; PSO-GA's fitness is the lanes'
  // distances (robot-blind, seed 003 eq. (1)).
  void UseFreeSpace(std::shared_ptr<const FreeSpaceMotion> motion) { free_space_ = std::move(motion); }
  // Seconds robot's plan for `task` (from its queue's end) takes beyond the lanes' when
  // AssignSingle refines it through free space (turns, crabs, spins; may be < 0): what the
  // auction adds to its T_d and AssignSingle to its queue's. 0 when it would not be refined;
  // +infinity when the task asks for a heading the hybrid A* cannot plan it into.
  double RefinedExtra(std::size_t robot, const PlanTask& task) const;
  // The same for `task` planned from point `from` (where an earlier task of a batch leaves
  // the robot) instead of its queue's end.
  double RefinedExtra(std::size_t robot, const PlanTask& task, PointId from) const;
  // Whether robot's segments are refined through free space (a four-wheel-steer robot, free
  // space in use): RefinedExtra is 0 for every other robot.
  bool Refines(std::size_t robot) const {
    return free_space_ && robots_.at(robot).info.kind == RobotKind::kFourWheelSteer;
  }

 private:
  struct RobotEntry;
  // `segment` (the lanes' plan of `task` for e) refined through free space when e is a
  // four-wheel-steer robot and free-space motion is in use; returns the seconds it gained at
  // its end (0: not refined). Errors: a heading the refinement cannot plan.
  Result<double> Refined(const RobotEntry& e, const PlanTask& task, Plan& segment) const;
  struct RobotEntry {
    FleetRobot info;
    std::vector<QueuedTask> queue;
    Plan plan;
    QueueSummary summary;
    TrafficPredictor::PlanHandle prediction;  // set by Publish
    std::uint64_t revision = 0;
  };
  FleetState() = default;
  // Appends `segment` (its waypoint 0 repeats the plan's end and is dropped) to the plan.
  static void AppendSegment(Plan& plan, const std::vector<Waypoint>& segment);
  // Appends a planned single task (segment starts at the queue's end) and updates the queue,
  // its summary and (publish) the prediction.
  void AppendTask(RobotEntry& e, const std::string& order_id, const PlanTask& task,
                  const std::vector<Waypoint>& segment, double travel, bool publish = true);
  // Gives the predictor robot e's plan plus a final wait of config_.hold_seconds.
  void Publish(RobotEntry& e);
  // Every time of e's queue, plan and summary + shift.
  static void Move(RobotEntry& e, double shift);
  // Appends the final wait of config_.hold_seconds to `plan` (none when <= 0), calls
  // `predict` with it, and takes it off again (no copy of the plan).
  template <typename Predict>
  void WithHold(Plan& plan, Predict predict) const;

  std::shared_ptr<const WarehouseMap> map_;
  std::shared_ptr<const RouteTable> routes_;
  AllocationConfig config_;
  std::vector<RobotEntry> robots_;
  std::unordered_map<std::string, std::size_t> index_;
  std::unique_ptr<TrafficPredictor> predictor_;
  std::shared_ptr<const FreeSpaceMotion> free_space_;
};

}  // namespace dispatch::engine
