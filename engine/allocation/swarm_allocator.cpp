#include "engine/allocation/swarm_allocator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <set>
#include <string>
#include <utility>

namespace dispatch::engine {

SwarmAllocator::SwarmAllocator(SwarmOptions options, std::size_t candidates,
                               std::chrono::milliseconds budget)
    : options_(std::move(options)), candidates_(std::max<std::size_t>(1, candidates)), budget_(budget) {}

Result<AwardExplanation> SwarmAllocator::Allocate(const Order& order, FleetState& state) {
  std::optional<Result<AwardExplanation>> out;
  AllocateBatch({&order}, state, [&](const Order&, Result<AwardExplanation> award) { out.emplace(std::move(award)); });
  return std::move(*out);  // every order of a batch reaches the sink once
}

void SwarmAllocator::AllocateBatch(const std::vector<const Order*>& orders, FleetState& state,
                                   const AwardSink& sink) {
  std::vector<const Order*> singles;
  std::vector<PlanTask> tasks;
  for (const Order* o : orders) {
    if (o->formation) {
      sink(*o, auction_.Allocate(*o, state));
      continue;
    }
    Result<PlanTask> task = PrepareOrder(*o, state);
    if (!task.ok()) {
      sink(*o, task.error());
      continue;
    }
    singles.push_back(o);
    tasks.push_back(std::move(task).value());
  }
  // The robots searched: for each order the `candidates_` with room that can start it soonest.
  // An order no robot with room reaches goes to the auction, which says why.
  const RouteTable& routes = state.routes();
  std::set<std::size_t> chosen;
  std::vector<std::pair<double, std::size_t>> ranked;
  std::size_t kept = 0;
  for (std::size_t j = 0; j < singles.size(); ++j) {
    const PlanTask& task = tasks[j];
    ranked.clear();
    for (std::size_t i = 0; i < state.robot_count(); ++i) {
      if (!state.HasRoom(i)) continue;
      const QueueSummary& s = state.summary(i);
      const double start = s.end_time + routes.Cost(s.end_point, task.picks.front());
      if (std::isfinite(start)) ranked.emplace_back(start, i);
    }
    if (ranked.empty()) {
      sink(*singles[j], auction_.Allocate(*singles[j], state));
      continue;
    }
    const std::size_t keep = std::min(candidates_, ranked.size());
    std::partial_sort(ranked.begin(), ranked.begin() + static_cast<std::ptrdiff_t>(keep), ranked.end());
    for (std::size_t k = 0; k < keep; ++k) chosen.insert(ranked[k].second);
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
