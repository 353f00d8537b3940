#include "engine/allocation/fleet_state.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/fleet/formation.h"

namespace dispatch::engine {

Status FleetState::UseRoutes(std::shared_ptr<const RouteTable> routes) {
  if (!routes) return InvalidArgument("fleet state: null route table");
  if (routes->point_count() != map_->point_count()) {
    return InvalidArgument("fleet state: a route table of " + std::to_string(routes->point_count()) +
                           " points for a map of " + std::to_string(map_->point_count()));
  }
  routes_ = std::move(routes);
  return Ok();
}

Result<FleetState> FleetState::Create(std::shared_ptr<const WarehouseMap> map,
                                      std::shared_ptr<const RouteTable> routes,
                                      const std::vector<FleetRobot>& robots,
                                      const AllocationConfig& config,
                                      std::shared_ptr<const ZoneIndex> zones, bool publish) {
  if (!map) return InvalidArgument("fleet state: null map");
  if (!routes) return InvalidArgument("fleet state: null route table");
  if (Status s = ValidateAllocationConfig(config); !s.ok()) return s.error();
  if (zones && (zones->zones().size() != map->zones().size() ||
                zones->requested_cell_size() != config.traffic.zone_cell_size)) {
    return InvalidArgument("fleet state: the zone index was built for another map or cell size");
  }
  FleetState state;
  state.map_ = std::move(map);
  state.routes_ = std::move(routes);
  state.config_ = config;
  state.predictor_ = zones ? std::make_unique<TrafficPredictor>(std::move(zones), config.traffic)
                           : std::make_unique<TrafficPredictor>(*state.map_, config.traffic);
  for (const FleetRobot& r : robots) {
    if (r.id.empty()) return InvalidArgument("fleet state: a robot has an empty id");
    if (state.index_.count(r.id) != 0) {
      return InvalidArgument("fleet state: duplicate robot id '" + r.id + "'");
    }
    if (r.start < 0 || static_cast<std::size_t>(r.start) >= state.map_->point_count()) {
      return NotFound("fleet state: robot '" + r.id + "' starts at unknown point id " +
                      std::to_string(r.start));
    }
    if (!std::isfinite(r.ready_time)) {
      return InvalidArgument("fleet state: robot '" + r.id + "' has a non-finite ready time");
    }
    RobotEntry e;
    e.info = r;
    e.summary.end_point = r.start;
    e.summary.end_time = r.ready_time;
    Waypoint w;
    w.point = r.start;
    w.xy = state.map_->point(r.start).position;
    w.eta = r.ready_time;
    e.plan.robot_id = r.id;
    e.plan.waypoints.push_back(w);
    state.index_.emplace(r.id, state.robots_.size());
    state.robots_.push_back(std::move(e));
  }
  if (publish) {
    for (RobotEntry& e : state.robots_) state.Publish(e);
  }
  return state;
}

std::optional<std::size_t> FleetState::FindRobot(const std::string& id) const {
  auto it = index_.find(id);
  if (it == index_.end()) return std::nullopt;
  return it->second;
}

PlanTask FleetState::TaskOf(const std::vector<PointId>& picks, PointId drop,
                            double order_work_time) const {
  PlanTask task;
  task.picks = picks;
  task.drop = drop;
  task.work_time = config_.work_time_override.value_or(order_work_time);
  task.drop_time = config_.drop_time.value_or(task.work_time);
  return task;
}

double FleetState::TaskTravelTime(const PlanTask& task) const {
  if (task.picks.empty()) return std::numeric_limits<double>::infinity();
  double total = 0.0;
  for (std::size_t k = 0; k + 1 < task.picks.size(); ++k) {
    total += routes_->Cost(task.picks[k], task.picks[k + 1]);
  }
  return total + routes_->Cost(task.picks.back(), task.drop);
}

void FleetState::AppendSegment(Plan& plan, const std::vector<Waypoint>& segment) {
  const std::size_t needed = plan.waypoints.size() + segment.size();
  if (plan.waypoints.capacity() < needed) plan.waypoints.reserve(std::max(needed, 2 * plan.waypoints.capacity()));
  for (std::size_t k = 1; k < segment.size(); ++k) {
    Waypoint w = segment[k];
    w.seq = static_cast<int>(plan.waypoints.size());
    plan.waypoints.push_back(w);
  }
}

template <typename Predict>
void FleetState::WithHold(Plan& plan, Predict predict) const {
  if (config_.hold_seconds <= 0.0) {
    predict(plan);
    return;
  }
  Waypoint w = plan.waypoints.back();
  w.seq = static_cast<int>(plan.waypoints.size());
  w.eta = w.departure();
  w.action = WaypointAction::kWait;
  w.dwell = config_.hold_seconds;
  plan.waypoints.push_back(w);
  predict(plan);
  plan.waypoints.pop_back();
}

void FleetState::Publish(RobotEntry& e) {
  WithHold(e.plan, [&](const Plan& held) { e.prediction = predictor_->SetPlan(e.info.id, held); });
  ++e.revision;
}

TrafficPredictor::Contribution FleetState::Trace(std::size_t robot) const {
  const RobotEntry& e = robots_.at(robot);
  return predictor_->Trace(e.info.id, e.plan, e.info.ready_time, std::max(0.0, config_.hold_seconds));
}

FleetState::RobotSnapshot FleetState::Snapshot(std::size_t robot) const {
  const RobotEntry& e = robots_.at(robot);
  return RobotSnapshot{e.queue, e.plan, e.summary, e.info.ready_time, Trace(robot)};
}

Status FleetState::Settle(std::size_t robot, std::size_t bucket, const TrafficPredictor::Contribution* trace) {
  if (robot >= robots_.size()) return NotFound("fleet state: unknown robot index " + std::to_string(robot));
  RobotEntry& e = robots_[robot];
  const TrafficPredictor::Contribution own = trace ? TrafficPredictor::Contribution{} : Trace(robot);
  const TrafficPredictionConfig& grid = predictor_->config();
  const double ready = grid.origin_time + static_cast<double>(bucket) * grid.bucket_seconds;
  Move(e, ready - e.info.ready_time);
  e.info.ready_time = ready;
  e.prediction = predictor_->SetTraced(e.info.id, trace ? *trace : own, bucket);
  ++e.revision;
  return Ok{};
}

void FleetState::Move(RobotEntry& e, double shift) {
  for (QueuedTask& q : e.queue) {
    q.start_time += shift;
    q.end_time += shift;
  }
  for (Waypoint& w : e.plan.waypoints) w.eta += shift;
  e.summary.end_time += shift;
}

Status FleetState::Restore(std::size_t robot, const RobotSnapshot& snapshot, std::size_t bucket) {
  if (robot >= robots_.size()) return NotFound("fleet state: unknown robot index " + std::to_string(robot));
  RobotEntry& e = robots_[robot];
  if (snapshot.plan.robot_id != e.info.id || snapshot.plan.waypoints.empty()) {
    return InvalidArgument("fleet state: a snapshot of another robot or of no plan for " + e.info.id);
  }
  const TrafficPredictionConfig& grid = predictor_->config();
  e.info.ready_time = grid.origin_time + static_cast<double>(bucket) * grid.bucket_seconds;
  e.info.start = snapshot.plan.waypoints.front().point;
  e.queue = snapshot.queue;  // element-wise: the entry's strings and vectors keep their storage
  e.plan.waypoints = snapshot.plan.waypoints;
  e.summary = snapshot.summary;
  Move(e, e.info.ready_time - snapshot.ready_time);
  e.prediction = predictor_->SetTraced(e.info.id, snapshot.trace, bucket);
  ++e.revision;
  return Ok{};
}

Status FleetState::Reset(std::size_t robot, PointId start, double ready_time) {
  if (robot >= robots_.size()) return NotFound("fleet state: unknown robot index " + std::to_string(robot));
  RobotEntry& e = robots_[robot];
  if (start < 0 || static_cast<std::size_t>(start) >= map_->point_count()) {
    return NotFound("fleet state: robot '" + e.info.id + "' starts at unknown point id " + std::to_string(start));
  }
  if (!std::isfinite(ready_time)) {
    return InvalidArgument("fleet state: robot '" + e.info.id + "' has a non-finite ready time");
  }
  e.info.start = start;
  e.info.ready_time = ready_time;
  e.queue.clear();
  e.summary = QueueSummary{start, ready_time, 0.0, 0.0};
  Waypoint w;
  w.point = start;
  w.xy = map_->point(start).position;
  w.eta = ready_time;
  e.plan.waypoints.assign(1, w);
  ++e.revision;
  return Ok{};
}

namespace {

// Stop headings keyed by stop index (picks, then the drop) re-keyed by the index of each
// stop's waypoint in `segment` (BuildPlan's one-task plan: its stops in order after the start).
std::map<std::size_t, double> StopWaypoints(const Plan& segment, const std::map<std::size_t, double>& by_stop) {
  std::map<std::size_t, double> out;
  if (by_stop.empty()) return out;
  std::size_t stop = 0;
  for (std::size_t w = 1; w < segment.waypoints.size(); ++w) {
    const WaypointAction a = segment.waypoints[w].action;
    if (a != WaypointAction::kPick && a != WaypointAction::kDrop) continue;
    if (auto it = by_stop.find(stop); it != by_stop.end()) out[w] = it->second;
    ++stop;
  }
  return out;
}

}  // namespace

Status FleetState::AssignSingle(std::size_t robot, const std::string& order_id,
                                const PlanTask& task) {
  if (robot >= robots_.size()) {
    return NotFound("order " + order_id + ": unknown robot index " + std::to_string(robot));
  }
  RobotEntry& e = robots_[robot];
  if (!CanServe(robot, task)) {
    return Error{ErrorCode::kFailedPrecondition,
                 "order " + order_id + " for robot " + e.info.id +
                     ": a stop's heading needs a four-wheel-steer robot planned through a free-space region"};
  }
  const QueueSummary& s = e.summary;
  Result<Plan> segment = BuildPlan(*map_, *routes_, s.end_point, s.end_time, config_.speed, {task}, config_.turn_time);
  if (!segment.ok()) {
    return Error{segment.error().code,
                 "order " + order_id + " for robot " + e.info.id + ": " + segment.error().message};
  }
  double travel = routes_->Cost(s.end_point, task.picks.front()) + TaskTravelTime(task);
  Result<double> extra = Refined(e, task, segment.value());
  if (!extra.ok()) {
    return Error{extra.error().code, "order " + order_id + " for robot " + e.info.id + ": " + extra.error().message};
  }
  travel += *extra;
  AppendTask(e, order_id, task, segment->waypoints, travel);
  return Ok{};
}

Result<double> FleetState::Refined(const RobotEntry& e, const PlanTask& task, Plan& segment) const {
  if (!free_space_ || e.info.kind != RobotKind::kFourWheelSteer) return 0.0;
  Result<Plan> refined = free_space_->Refine(segment, config_.speed, StopWaypoints(segment, task.stop_headings));
  if (!refined.ok()) {
    if (task.stop_headings.empty()) return 0.0;  // its lanes
    // Its lanes cannot give the heading.
    return Error{refined.error().code, "the heading asked for cannot be planned: " + refined.error().message};
  }
  // The same stops and work: the difference at the end is driving and turning.
  const double extra = refined->waypoints.back().eta - segment.waypoints.back().eta;
  segment = std::move(refined).value();
  return extra;
}

double FleetState::RefinedExtra(std::size_t robot, const PlanTask& task) const {
  return RefinedExtra(robot, task, robots_.at(robot).summary.end_point);
}

double FleetState::RefinedExtra(std::size_t robot, const PlanTask& task, PointId from) const {
  if (!Refines(robot) || !CanServe(robot, task)) return 0.0;
  const RobotEntry& e = robots_.at(robot);
  const QueueSummary& s = e.summary;
  Result<Plan> segment = BuildPlan(*map_, *routes_, from, s.end_time, config_.speed, {task}, config_.turn_time);
  if (!segment.ok()) return 0.0;  // the bid finds it unreachable on its own
  Result<double> extra = Refined(e, task, segment.value());
  return extra.ok() ? *extra : std::numeric_limits<double>::infinity();
}

void FleetState::AppendTask(RobotEntry& e, const std::string& order_id, const PlanTask& task,
                            const std::vector<Waypoint>& segment, double travel, bool publish) {
  QueuedTask q{order_id, task, {e.info.id}, e.summary.end_time, segment.back().departure()};
  AppendSegment(e.plan, segment);
  e.summary.end_point = task.drop;
  e.summary.end_time = e.plan.end_time();
  e.summary.travel_time += travel;
  e.summary.work_time += TaskWorkTime(task);
  e.queue.push_back(std::move(q));
  ++e.revision;
  if (publish) Publish(e);
}

Status FleetState::AssignPlanned(std::size_t robot, const std::string& order_id, const PlanTask& task,
                                 std::vector<Waypoint> segment, bool publish) {
  if (robot >= robots_.size()) {
    return NotFound("order " + order_id + ": unknown robot index " + std::to_string(robot));
  }
  if (segment.size() < 2) return InvalidArgument("order " + order_id + ": a planned segment needs 2 waypoints");
  RobotEntry& e = robots_[robot];
  const double shift = e.summary.end_time - segment.front().eta;
  double travel = 0.0;
  for (std::size_t k = 1; k < segment.size(); ++k) {
    const double drive = segment[k].eta - segment[k - 1].departure();
    if (!(drive >= -1e-9)) {
      return InvalidArgument("order " + order_id + ": planned waypoint " + std::to_string(k) + " arrives before " +
                             "the previous one is left");
    }
    travel += std::max(0.0, drive);
  }
  if (segment.back().point != task.drop) {
    return InvalidArgument("order " + order_id + ": a planned segment must end at the task's drop");
  }
  for (Waypoint& w : segment) w.eta += shift;
  AppendTask(e, order_id, task, segment, travel, publish);
  return Ok{};
}

Status FleetState::AssignFormation(const std::array<std::size_t, 3>& team,
                                   const std::string& order_id, const PlanTask& task) {
  for (std::size_t i = 0; i < team.size(); ++i) {
    if (team[i] >= robots_.size()) {
      return NotFound("order " + order_id + ": unknown robot index " + std::to_string(team[i]));
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (team[i] == team[j]) {
        return InvalidArgument("order " + order_id + ": formation member " +
                               robots_[team[i]].info.id + " appears twice");
      }
    }
  }
  if (task.picks.empty()) return InvalidArgument("order " + order_id + ": no pick points");
  std::vector<PointId> starts;
  for (std::size_t m : team) starts.push_back(robots_[m].summary.end_point);
  // Built from time 0, then each member's leg is shifted to its own ready time and the
  // formation part to the common rendezvous time T_r.
  Result<FormationPlans> f = BuildFormationPlans(*map_, *routes_, starts, 0.0, config_.speed,
                                                 task, config_.formation);
  if (!f.ok()) {
    return Error{f.error().code, "order " + order_id + ": " + f.error().message};
  }
  FormationPlans& plans = f.value();
  double rendezvous = 0.0;
  for (std::size_t i = 0; i < team.size(); ++i) {
    const Waypoint& slot = plans.members[i].waypoints[plans.formation_start[i] - 1];
    rendezvous = std::max(rendezvous, slot.eta + robots_[team[i]].summary.end_time);
  }
  const double formation_shift = rendezvous - plans.rendezvous_time;
  const double task_travel = TaskTravelTime(task);
  for (std::size_t i = 0; i < team.size(); ++i) {
    RobotEntry& e = robots_[team[i]];
    std::vector<Waypoint>& w = plans.members[i].waypoints;
    const std::size_t fs = plans.formation_start[i];
    for (std::size_t k = 0; k < fs; ++k) w[k].eta += e.summary.end_time;
    w[fs - 1].dwell = rendezvous - w[fs - 1].eta;  // the slot: wait for the last member
    for (std::size_t k = fs; k < w.size(); ++k) w[k].eta += formation_shift;
    const double travel = routes_->Cost(e.summary.end_point, task.picks.front()) + task_travel;
    std::vector<std::string> names;
    for (std::size_t m : team) names.push_back(robots_[m].info.id);
    QueuedTask q{order_id, task, std::move(names), e.summary.end_time, 0.0};
    AppendSegment(e.plan, w);
    e.summary.end_point = task.drop;
    e.summary.end_time = e.plan.end_time();
    e.summary.travel_time += travel;
    e.summary.work_time += TaskWorkTime(task);
    q.end_time = e.summary.end_time;
    e.queue.push_back(std::move(q));
    Publish(e);
  }
  return Ok{};
}

}  // namespace dispatch::engine
