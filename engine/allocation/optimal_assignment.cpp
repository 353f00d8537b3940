#include "engine/allocation/optimal_assignment.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>

#include "engine/allocation/allocator.h"
#include "engine/common/numbers.h"

namespace dispatch::engine {
namespace {

struct BatchTask {
  PointId first = kNoPoint;
  PointId drop = kNoPoint;
  double travel = 0.0;  // pick -> ... -> drop
  double work = 0.0;    // n_c * t_w + drop times
  PlanTask task;        // for the refined legs (FleetState::RefinedExtra)
};

Result<std::vector<BatchTask>> Prepare(const FleetState& state, const std::vector<Order>& orders) {
  std::vector<BatchTask> tasks;
  for (const Order& o : orders) {
    if (o.formation) {
      return InvalidArgument("order " + o.id + ": optimal assignment handles single-robot orders "
                             "only, this one needs a formation");
    }
    Result<PlanTask> t = PrepareOrder(o, state);
    if (!t.ok()) return t.error();
    tasks.push_back({t->picks.front(), t->drop, state.TaskTravelTime(*t), TaskWorkTime(*t), *t});
  }
  return tasks;
}

// FleetState::RefinedExtra of task k for robot r from point `from`, each asked once: the brute
// force prices the same legs in many maps, and for a four-wheel-steer robot each is a hybrid
// A* search (every other robot: 0 at once, not remembered).
class RefinedLegs {
 public:
  RefinedLegs(const FleetState& state, const std::vector<BatchTask>& tasks) : state_(state), tasks_(tasks) {}
  double operator()(std::size_t r, std::size_t k, PointId from) {
    if (!state_.Refines(r)) return 0.0;
    const std::uint64_t key =
        (static_cast<std::uint64_t>(r) * tasks_.size() + k) * state_.map().point_count() + static_cast<std::uint64_t>(from);
    auto [it, fresh] = known_.try_emplace(key, 0.0);
    if (fresh) it->second = state_.RefinedExtra(r, tasks_[k].task, from);
    return it->second;
  }

 private:
  const FleetState& state_;
  const std::vector<BatchTask>& tasks_;
  std::unordered_map<std::uint64_t, double> known_;
};

// Over the robots (all, or `only`): eq. (1) of each final queue, or of each queue up to every
// order of the batch it takes (the bid sum).
double Total(const FleetState& state, const std::vector<BatchTask>& tasks, RefinedLegs& refined,
             const std::vector<std::size_t>& robot_of_order, const std::vector<std::size_t>* only,
             BatchObjective objective) {
  const AllocationConfig& c = state.config();
  double total = 0.0;
  const std::size_t count = only ? only->size() : state.robot_count();
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t r = only ? (*only)[i] : i;
    const QueueSummary& s = state.summary(r);
    double travel = s.travel_time;
    double work = s.work_time;
    PointId at = s.end_point;
    for (std::size_t k = 0; k < tasks.size(); ++k) {
      if (robot_of_order[k] != r) continue;
      // A four-wheel-steer robot's legs through free space, as AssignSingle will plan them.
      travel += state.routes().Cost(at, tasks[k].first) + tasks[k].travel + refined(r, k, at);
      work += tasks[k].work;
      at = tasks[k].drop;
      if (objective == BatchObjective::kBidSum) total += c.alpha * (travel + work) + c.beta * travel;
    }
    if (objective == BatchObjective::kQueueTotals) {
      total += c.alpha * (travel + work) + c.beta * travel;  // Chu2024 eqs. (1)-(3)
    }
  }
  return total;
}

}  // namespace

Result<double> BatchCost(const FleetState& state, const std::vector<Order>& orders,
                         const std::vector<std::size_t>& robot_of_order, BatchObjective objective) {
  if (robot_of_order.size() != orders.size()) {
    return InvalidArgument("batch cost: " + std::to_string(orders.size()) + " orders but " +
                           std::to_string(robot_of_order.size()) + " robot indices");
  }
  for (std::size_t r : robot_of_order) {
    if (r >= state.robot_count()) return NotFound("batch cost: unknown robot index " + std::to_string(r));
  }
  Result<std::vector<BatchTask>> tasks = Prepare(state, orders);
  if (!tasks.ok()) return tasks.error();
  RefinedLegs refined(state, *tasks);
  return Total(state, *tasks, refined, robot_of_order, nullptr, objective);
}

Result<BatchAssignment> BruteForceAssignment(const FleetState& state,
                                             const std::vector<Order>& orders,
                                             const OptimalAssignmentOptions& options) {
  Result<std::vector<BatchTask>> tasks = Prepare(state, orders);
  if (!tasks.ok()) return tasks.error();
  RefinedLegs refined(state, *tasks);
  std::vector<std::size_t> robots = options.robots;
  if (robots.empty()) {
    for (std::size_t r = 0; r < state.robot_count(); ++r) robots.push_back(r);
  }
  for (std::size_t k = 0; k < robots.size(); ++k) {
    if (robots[k] >= state.robot_count()) {
      return NotFound("brute force: unknown robot index " + std::to_string(robots[k]));
    }
    if (k > 0 && robots[k] <= robots[k - 1]) {
      return InvalidArgument("brute force: the robot subset must be ascending without repeats");
    }
  }
  const std::size_t m = robots.size();
  const std::size_t n = orders.size();
  if (m == 0 && n > 0) return Error{ErrorCode::kFailedPrecondition, "brute force: no robots"};
  double maps = 1.0;
  for (std::size_t k = 0; k < n; ++k) maps *= static_cast<double>(m);
  if (maps > static_cast<double>(options.max_maps)) {
    return Error{ErrorCode::kFailedPrecondition,
                 "brute force: " + std::to_string(m) + "^" + std::to_string(n) +
                     " maps exceed the limit of " + std::to_string(options.max_maps)};
  }
  // Places left per robot of the subset (one per order when injective).
  std::vector<std::size_t> room(m, n);
  for (std::size_t i = 0; i < m; ++i) {
    if (options.one_order_per_robot) room[i] = 1;
    const std::size_t max_queue = state.config().max_queue;
    if (options.respect_queue_room && max_queue != 0) {
      const std::size_t held = state.queue(robots[i]).size();
      room[i] = std::min(room[i], held >= max_queue ? 0 : max_queue - held);
    }
  }
  // The robots outside the subset add the same constant to every map: only the subset's
  // queues are compared, the winner's full BatchCost is reported.
  BatchAssignment best{{}, kInf};
  std::vector<std::size_t> map(n, 0);
  std::size_t visited = 0;
  bool stopped = false;
  // Lexicographic enumeration: order 0's robot varies slowest.
  auto visit = [&](auto&& self, std::size_t k) -> void {
    if (stopped) return;
    if (k == n) {
      if (options.stop && (++visited & 4095u) == 0 && options.stop()) {
        stopped = true;
        return;
      }
      const double cost = Total(state, *tasks, refined, map, &robots, options.objective);
      if (cost < best.cost) best = {map, cost};
      return;
    }
    for (std::size_t i = 0; i < m; ++i) {
      if (room[i] == 0) continue;
      map[k] = robots[i];
      --room[i];
      self(self, k + 1);
      ++room[i];
    }
  };
  visit(visit, 0);
  if (stopped) {
    return Error{ErrorCode::kFailedPrecondition,
                 "brute force: stopped after " + std::to_string(visited) + " maps"};
  }
  if (!std::isfinite(best.cost)) {
    return Unreachable("brute force: no assignment of the " + std::to_string(n) +
                       " orders has a finite cost");
  }
  best.cost = Total(state, *tasks, refined, best.robot_of_order, nullptr, options.objective);
  return best;
}

namespace {

// Marginal cost of appending each order to each robot's queue (rows: orders; columns: the
// robots), unreachable = kBig.
constexpr double kBig = 1e15;

std::vector<std::vector<double>> MarginalCosts(const FleetState& state, const std::vector<BatchTask>& tasks,
                                               const std::vector<std::size_t>& robots) {
  const AllocationConfig& c = state.config();
  std::vector<std::vector<double>> cost(tasks.size(), std::vector<double>(robots.size(), kBig));
  for (std::size_t k = 0; k < tasks.size(); ++k) {
    for (std::size_t j = 0; j < robots.size(); ++j) {
      const BatchTask& t = tasks[k];
      const double travel = state.routes().Cost(state.summary(robots[j]).end_point, t.first) + t.travel +
                            state.RefinedExtra(robots[j], t.task);
      const double value = c.alpha * (travel + t.work) + c.beta * travel;
      if (std::isfinite(value)) cost[k][j] = value;
    }
  }
  return cost;
}

// The Hungarian method (potentials, O(n^2 m)) on an n x m cost matrix with n <= m: the column
// of each row, distinct, at the least total.
std::vector<std::size_t> SolveRows(const std::vector<std::vector<double>>& cost, std::size_t n, std::size_t m) {
  // 1-based: a[i][j] for rows 1..n and columns 1..m; p[j] = the row of column j.
  std::vector<double> u(n + 1, 0.0), v(m + 1, 0.0);
  std::vector<std::size_t> p(m + 1, 0), way(m + 1, 0);
  for (std::size_t i = 1; i <= n; ++i) {
    p[0] = i;
    std::size_t j0 = 0;
    std::vector<double> minv(m + 1, kInf);
    std::vector<bool> used(m + 1, false);
    do {
      used[j0] = true;
      const std::size_t i0 = p[j0];
      double delta = kInf;
      std::size_t j1 = 0;
      for (std::size_t j = 1; j <= m; ++j) {
        if (used[j]) continue;
        const double cur = cost[i0 - 1][j - 1] - u[i0] - v[j];
        if (cur < minv[j]) {
          minv[j] = cur;
          way[j] = j0;
        }
        if (minv[j] < delta) {
          delta = minv[j];
          j1 = j;
        }
      }
      for (std::size_t j = 0; j <= m; ++j) {
        if (used[j]) {
          u[p[j]] += delta;
          v[j] -= delta;
        } else {
          minv[j] -= delta;
        }
      }
      j0 = j1;
    } while (p[j0] != 0);
    do {
      const std::size_t j1 = way[j0];
      p[j0] = p[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  std::vector<std::size_t> column_of_row(n, 0);
  for (std::size_t j = 1; j <= m; ++j) {
    if (p[j] != 0) column_of_row[p[j] - 1] = j - 1;
  }
  return column_of_row;
}

}  // namespace

Result<BatchAssignment> HungarianAssignment(const FleetState& state,
                                            const std::vector<Order>& orders) {
  Result<std::vector<BatchTask>> tasks = Prepare(state, orders);
  if (!tasks.ok()) return tasks.error();
  const std::size_t n = orders.size();
  const std::size_t m = state.robot_count();
  if (n > m) {
    return Error{ErrorCode::kFailedPrecondition,
                 "hungarian: " + std::to_string(n) + " orders but only " + std::to_string(m) +
                     " robots (one order per robot)"};
  }
  std::vector<std::size_t> all(m);
  for (std::size_t r = 0; r < m; ++r) all[r] = r;
  BatchAssignment result;
  result.robot_of_order = SolveRows(MarginalCosts(state, *tasks, all), n, m);
  RefinedLegs refined(state, *tasks);
  result.cost = Total(state, *tasks, refined, result.robot_of_order, nullptr, BatchObjective::kQueueTotals);
  if (!std::isfinite(result.cost)) {
    return Unreachable("hungarian: no one-order-per-robot assignment of the " +
                       std::to_string(n) + " orders has a finite cost");
  }
  return result;
}

Result<BatchAssignment> OneToOneAssignment(const FleetState& state, const std::vector<Order>& orders,
                                           const std::vector<std::size_t>& robots) {
  Result<std::vector<BatchTask>> tasks = Prepare(state, orders);
  if (!tasks.ok()) return tasks.error();
  for (std::size_t r : robots) {
    if (r >= state.robot_count()) return InvalidArgument("one-to-one: unknown robot index " + std::to_string(r));
  }
  const std::vector<std::vector<double>> cost = MarginalCosts(state, *tasks, robots);
  const std::size_t n = orders.size();
  const std::size_t m = robots.size();
  BatchAssignment result;
  result.robot_of_order.assign(n, kNoRobot);
  if (n == 0 || m == 0) return result;
  if (n <= m) {
    const std::vector<std::size_t> column = SolveRows(cost, n, m);
    for (std::size_t k = 0; k < n; ++k) result.robot_of_order[k] = column[k];
  } else {  // more orders than robots: rows are the robots
    std::vector<std::vector<double>> transposed(m, std::vector<double>(n));
    for (std::size_t k = 0; k < n; ++k) {
      for (std::size_t j = 0; j < m; ++j) transposed[j][k] = cost[k][j];
    }
    const std::vector<std::size_t> order_of_robot = SolveRows(transposed, m, n);
    for (std::size_t j = 0; j < m; ++j) result.robot_of_order[order_of_robot[j]] = j;
  }
  for (std::size_t k = 0; k < n; ++k) {
    std::size_t& j = result.robot_of_order[k];
    if (j == kNoRobot) continue;
    if (cost[k][j] >= kBig) {  // matched only because something had to be: no route
      j = kNoRobot;
      continue;
    }
    result.cost += cost[k][j];
    j = robots[j];
  }
  return result;
}

}  // namespace dispatch::engine
