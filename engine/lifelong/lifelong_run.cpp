#include "engine/lifelong/lifelong_run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <unordered_map>
#include <utility>

#include "engine/allocation/fleet_state.h"
#include "engine/dispatch/strategy.h"
#include "engine/lifelong/turn_pibt.h"

namespace dispatch::engine {
namespace {

struct OpenTask {
  RevealedTask task;
  int done = 0;     // errands done
  int robot = -1;   // the robot holding it
};

class Run {
 public:
  Run(const LorrProblem& problem, const LifelongOptions& options, std::unique_ptr<Allocator> allocator,
      std::shared_ptr<const RouteTable> routes)
      : problem_(problem),
        options_(options),
        grid_(problem.grid),
        allocator_(std::move(allocator)),
        routes_(routes),
        planner_(problem.grid, std::move(routes), options.seed) {
    const std::size_t n = problem.starts.size();
    record_.strategy = std::string(allocator_->name());
    record_.routes = std::string(routes_->method());
    record_.team_size = static_cast<int>(n);
    for (int cell : problem.starts) poses_.push_back({cell, 0});
    record_.starts = poses_;
    record_.actual_actions.assign(n, {});
    record_.planner_actions.assign(n, {});
    record_.actual_schedule.assign(n, {});
    record_.planner_schedule.assign(n, {});
    task_of_.assign(n, -1);
    busy_steps_.assign(n, 0);
  }

  Result<LifelongRecord> Go() {
    Reveal(0);
    int t = 0;
    while (t < options_.steps && !(options_.cancelled && options_.cancelled())) {
      const auto begin = std::chrono::steady_clock::now();
      if (Status scheduled = Schedule(t); !scheduled) return scheduled.error();
      std::vector<int> goals(poses_.size(), -1);
      for (std::size_t r = 0; r < poses_.size(); ++r) {
        if (task_of_[r] == -1) continue;
        const OpenTask& open = open_.at(task_of_[r]);
        goals[r] = open.task.errands[static_cast<std::size_t>(open.done)];
        ++busy_steps_[r];
      }
      std::vector<GridAction> actions = planner_.Step(poses_, goals);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
      record_.planner_seconds.push_back(seconds);
      if (options_.plan_ms > 0.0 && seconds * 1000.0 > options_.plan_ms) {
        ++record_.entry_timeouts;
        const int late = static_cast<int>(std::floor(seconds * 1000.0 / options_.plan_ms));
        for (int k = 0; k < late && t < options_.steps; ++k, ++t) {
          for (std::size_t r = 0; r < poses_.size(); ++r) {
            record_.actual_actions[r] += 'T';
            record_.planner_actions[r] += 'T';
            if (goals[r] != -1) ++busy_steps_[r];
          }
        }
        if (t >= options_.steps) break;
      }
      Move(t, actions);
      ++t;
      Errands(t);
      Reveal(t);
    }
    record_.steps = t;
    for (int steps : busy_steps_) record_.makespan = std::max(record_.makespan, steps);
    return std::move(record_);
  }

 private:
  void Reveal(int step) {
    const int want = problem_.reveal_count();
    while (static_cast<int>(open_.size()) < want && !problem_.tasks.empty()) {
      const LorrTask& source = problem_.tasks[static_cast<std::size_t>(next_task_) % problem_.tasks.size()];
      OpenTask open;
      open.task = {next_task_, step, source.errands};
      record_.tasks.push_back(open.task);
      waiting_.push_back(next_task_);
      open_.emplace(next_task_, std::move(open));
      ++next_task_;
    }
  }

  // Step 1: the waiting tasks to the free robots, through the product's allocator (with
  // reassign, also the tasks not opened yet to their robots and the free ones).
  Status Schedule(int step) {
    std::vector<FleetRobot> free;
    std::vector<int> robot_of_entry;
    std::vector<int> pool = waiting_;
    std::vector<std::pair<int, int>> held;  // (robot, task): tasks back in the pool
    bool reassign = options_.reassign;
    if (reassign) {  // only a pool within the bound and the credit (LifelongOptions::reassign)
      credit_ = std::min(credit_ + options_.reassign_work_per_step, options_.reassign_max_work);
      double robots = 0.0, tasks = static_cast<double>(waiting_.size());
      for (std::size_t r = 0; r < poses_.size(); ++r) {
        const bool unopened = task_of_[r] != -1 && open_.at(task_of_[r]).done == 0;
        robots += task_of_[r] == -1 || unopened ? 1.0 : 0.0;
        tasks += unopened ? 1.0 : 0.0;
      }
      const double work = std::min(robots, tasks) * std::min(robots, tasks) * std::max(robots, tasks);
      reassign = work <= options_.reassign_max_work && work <= credit_;
      if (reassign) credit_ -= work;
      record_.reassign_steps += reassign ? 1 : 0;
    }
    for (std::size_t r = 0; r < poses_.size(); ++r) {
      if (task_of_[r] != -1) {
        OpenTask& open = open_.at(task_of_[r]);
        if (!reassign || open.done > 0) continue;
        held.emplace_back(static_cast<int>(r), task_of_[r]);
        pool.push_back(task_of_[r]);
        open.robot = -1;
        task_of_[r] = -1;
      }
      free.push_back({"r" + std::to_string(r), grid_.PointAt(poses_[r].cell), 0.0, RobotKind::kDifferential});
      robot_of_entry.push_back(static_cast<int>(r));
    }
    std::sort(pool.begin(), pool.end());  // reveal order
    if (free.empty() || pool.empty()) return Ok{};
    AllocationConfig config;
    config.max_queue = 1;
    Result<FleetState> state = FleetState::Create(grid_.map(), routes_, free, config, zones_);
    if (!state) return state.error();
    zones_ = state->zone_index();
    std::vector<Order> orders;
    orders.reserve(pool.size());
    for (int id : pool) {
      const RevealedTask& task = open_.at(id).task;
      Order order;
      order.id = std::to_string(id);
      for (std::size_t k = 0; k + 1 < task.errands.size(); ++k) order.picks.push_back(grid_.PointAt(task.errands[k]));
      order.drop = grid_.PointAt(task.errands.back());
      if (order.picks.empty()) order.picks.push_back(order.drop);
      order.work_time = 0.0;
      order.created_time = task.release_step;
      orders.push_back(std::move(order));
    }
    std::vector<const Order*> batch;
    for (const Order& order : orders) batch.push_back(&order);
    allocator_->AllocateBatch(batch, state.value(), [&](const Order& order, Result<AwardExplanation> award) {
      if (!award || award->winners.empty()) return;
      const std::optional<std::size_t> entry = state->FindRobot(award->winners.front());
      if (!entry) return;
      const int robot = robot_of_entry[*entry];
      const int id = std::stoi(order.id);
      task_of_[static_cast<std::size_t>(robot)] = id;
      open_.at(id).robot = robot;
    });
    // A robot that won nothing keeps its task if nobody else won it.
    for (const auto& [robot, id] : held) {
      OpenTask& open = open_.at(id);
      if (task_of_[static_cast<std::size_t>(robot)] == -1 && open.robot == -1) {
        task_of_[static_cast<std::size_t>(robot)] = id;
        open.robot = robot;
      }
    }
    // Schedule entries for the robots whose task changed.
    std::vector<int> before(poses_.size(), -1);
    for (const auto& [robot, id] : held) before[static_cast<std::size_t>(robot)] = id;
    for (int robot : robot_of_entry) {
      const auto r = static_cast<std::size_t>(robot);
      if (task_of_[r] == before[r]) continue;
      record_.planner_schedule[r].emplace_back(step + 1, task_of_[r]);
      record_.actual_schedule[r].emplace_back(step + 1, task_of_[r]);
    }
    waiting_.clear();
    for (int id : pool) {
      if (open_.at(id).robot == -1) waiting_.push_back(id);
    }
    return Ok{};
  }

  // Step 3: the planned actions if the joint step is legal, else everyone waits.
  void Move(int step, const std::vector<GridAction>& actions) {
    std::vector<StepViolation> violations = CheckJointStep(grid_, poses_, actions);
    const bool legal = violations.empty();
    if (!legal) {
      ++record_.planner_errors;
      record_.errors.push_back({violations[0].robot, violations[0].other, step + 1, violations[0].what});
    }
    for (std::size_t r = 0; r < poses_.size(); ++r) {
      record_.planner_actions[r] += static_cast<char>(actions[r]);
      const GridAction action = legal ? actions[r] : GridAction::kWait;
      record_.actual_actions[r] += static_cast<char>(action);
      poses_[r] = Apply(grid_, poses_[r], action);
    }
  }

  // Step 4, at `step` (after the move).
  void Errands(int step) {
    for (std::size_t r = 0; r < poses_.size(); ++r) {
      if (task_of_[r] == -1) continue;
      OpenTask& open = open_.at(task_of_[r]);
      if (poses_[r].cell != open.task.errands[static_cast<std::size_t>(open.done)]) continue;
      ++open.done;
      record_.events.push_back({step, static_cast<int>(r), open.task.id, open.done});
      if (open.done < static_cast<int>(open.task.errands.size())) continue;
      ++record_.tasks_finished;
      open_.erase(task_of_[r]);
      task_of_[r] = -1;
      record_.actual_schedule[r].emplace_back(step, -1);
      record_.planner_schedule[r].emplace_back(step, -1);
    }
  }

  const LorrProblem& problem_;
  const LifelongOptions& options_;
  const LorrGrid& grid_;
  std::unique_ptr<Allocator> allocator_;
  std::shared_ptr<const RouteTable> routes_;
  TurnPibt planner_;
  std::shared_ptr<const ZoneIndex> zones_;
  LifelongRecord record_;
  std::vector<GridPose> poses_;
  std::vector<int> task_of_;  // per robot: the task id it holds, -1
  std::vector<int> busy_steps_;
  std::unordered_map<int, OpenTask> open_;  // revealed, unfinished tasks by id
  std::vector<int> waiting_;                // open tasks no robot holds, in reveal order
  int next_task_ = 0;
  double credit_ = 0.0;  // reassignment work the steps so far allow (LifelongOptions::reassign)
};

}  // namespace

Result<LifelongRecord> RunLifelong(const LorrProblem& problem, const LifelongOptions& options) {
  if (options.steps < 0) return InvalidArgument("steps must be >= 0, got " + std::to_string(options.steps));
  if (!(options.plan_ms >= 0.0) || !std::isfinite(options.plan_ms)) {
    return InvalidArgument("plan_ms must be finite and >= 0");
  }
  if (problem.starts.empty()) return InvalidArgument("the problem has no robots");
  for (const auto& [name, value] : {std::pair{"reassign_max_work", options.reassign_max_work},
                                    std::pair{"reassign_work_per_step", options.reassign_work_per_step}}) {
    if (!(value >= 0.0) || !std::isfinite(value)) {
      return InvalidArgument(std::string(name) + " must be finite and >= 0, got " + std::to_string(value));
    }
  }
  Result<std::unique_ptr<Allocator>> allocator = MakeAllocator(options.strategy);
  if (!allocator) return allocator.error();
  RouteTableOptions route_options;
  route_options.lazy_cache_bytes = options.route_cache_bytes;
  route_options.method = options.route_method;
  Result<std::unique_ptr<RouteTable>> routes = MakeRouteTable(problem.grid.map(), route_options);
  if (!routes) return routes.error();
  Run run(problem, options, std::move(allocator).value(), std::shared_ptr<const RouteTable>(std::move(routes).value()));
  return run.Go();
}

}  // namespace dispatch::engine
