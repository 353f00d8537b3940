#include "engine/allocation/swarm_allocator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include <utility>

#include "engine/allocation/batch_orders.h"

namespace dispatch::engine {

SwarmAllocator::SwarmAllocator(SwarmOptions options, std::size_t candidates,
                               std::chrono::milliseconds budget)
    : options_(std::move(options)), candidates_(std::max<std::size_t>(1, candidates)), budget_(budget) {}

Result<AwardExplanation> SwarmAllocator::Allocate(const Order& order, FleetState& state) {
  return AllocateAsBatch(*this, order, state);
}

void SwarmAllocator::AllocateBatch(const std::vector<const Order*>& orders, FleetState& state,
                                   const AwardSink& sink) {
  BatchSingles taken = TakeSingles(orders, state, auction_, sink);
  std::vector<const Order*>& singles = taken.orders;
  std::vector<PlanTask>& tasks = taken.tasks;
  // The robots searched: for each order the `candidates_` with room that can start it soonest.
  // An order no robot with room reaches goes to the auction, which says why.
  const RouteTable& routes = state.routes();
  std::set<std::size_t> chosen;
  std::size_t kept = 0;
  for (std::size_t j = 0; j < singles.size(); ++j) {
    const std::vector<std::size_t> soonest = SoonestRobots(state, tasks[j], candidates_);
    if (soonest.empty()) {
      sink(*singles[j], auction_.Allocate(*singles[j], state));
      continue;
    }
    chosen.insert(soonest.begin(), soonest.end());
    singles[kept] = singles[j];
    tasks[kept++] = tasks[j];
  }
  singles.resize(kept);
  tasks.resize(kept);
  if (singles.empty()) return;
  const std::vector<std::size_t> robots(chosen.begin(), chosen.end());

  SwarmProblem problem;
  for (std::size_t i : robots) problem.robots.push_back({state.summary(i).end_point, 0.0});
  for (const PlanTask& task : tasks) {
    problem.tasks.push_back({task.picks.front(), 0.0, task.drop, state.TaskTravelTime(task)});
  }
  problem.distance = [&routes](PointId from, PointId to) { return routes.Cost(from, to); };
  SwarmOptions options = options_;
  options.deadline = std::chrono::steady_clock::now() + budget_;
  Result<SwarmPlan> plan = PlanSwarm(problem, options);
  if (!plan.ok()) {
    for (const Order* o : singles) sink(*o, plan.error());
    return;
  }
  if (!std::isfinite(plan->fitness)) {  // no plan of the encoding chains every order (one-way lanes)
    for (const Order* o : singles) sink(*o, auction_.Allocate(*o, state));
    return;
  }

  // Commit each robot's share in its execution order.
  char buf[160];
  for (std::size_t k = 0; k < robots.size(); ++k) {
    const std::vector<std::size_t>& sequence = plan->sequences[k];
    for (std::size_t n = 0; n < sequence.size(); ++n) {
      const Order& order = *singles[sequence[n]];
      const std::size_t robot = robots[k];
      if (!state.HasRoom(robot)) {
        sink(order, auction_.Allocate(order, state));
        continue;
      }
      const QueueSummary before = state.summary(robot);
      if (Status s = state.AssignSingle(robot, order.id, tasks[sequence[n]]); !s.ok()) {
        sink(order, s.error());
        continue;
      }
      AwardExplanation ex;
      ex.order_id = order.id;
      ex.strategy = std::string(name());
      Bid bid;
      bid.robot = state.robot_id(robot);
      bid.ready_time = before.end_time;
      bid.t_d = routes.Cost(before.end_point, tasks[sequence[n]].picks.front());
      bid.bid = bid.t_d;
      ex.bids.push_back(bid);
      ex.winners.push_back(bid.robot);
      std::snprintf(buf, sizeof(buf),
                    "%s over %zu orders and %zu robots: task %zu of %zu for %s (eq. (1) %.2f: "
                    "f_min %.2f, f_all %.2f)",
                    ex.strategy.c_str(), singles.size(), robots.size(), n + 1, sequence.size(),
                    bid.robot.c_str(), plan->fitness, plan->f_min, plan->f_all);
      ex.reason = buf;
      sink(order, std::move(ex));
    }
  }
}

}  // namespace dispatch::engine
