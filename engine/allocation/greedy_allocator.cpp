#include "engine/allocation/greedy_allocator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <tuple>

namespace dispatch::engine {

Result<AwardExplanation> GreedyAllocator::Allocate(const Order& order, FleetState& state) {
  Result<PlanTask> task = PrepareOrder(order, state);
  if (!task.ok()) return task.error();
  const PointId first = task->picks.front();
  AwardExplanation ex;
  ex.order_id = order.id;
  ex.strategy = std::string(name());
  std::vector<std::size_t> ranked;
  for (std::size_t i = 0; i < state.robot_count(); ++i) {
    const QueueSummary& s = state.summary(i);
    Bid b;
    b.robot = state.robot_id(i);
    b.ready_time = s.end_time;
    // A four-wheel-steer robot's drive through free space, as AssignSingle will plan it.
    b.t_d = state.routes().Cost(s.end_point, first) + (order.formation ? 0.0 : state.RefinedExtra(i, *task));
    b.queue_full = !state.HasRoom(i, order.formation);
    b.reachable = std::isfinite(b.t_d) && !b.queue_full && state.CanServe(i, *task);
    b.bid = b.t_d;
    if (b.reachable) ranked.push_back(i);
    ex.bids.push_back(std::move(b));
  }
  // Wang2019: idle robots first (nearest), then the earliest free (then nearest).
  auto key = [&](std::size_t i) {
    const bool idle = state.queue(i).empty();
    return std::make_tuple(idle ? 0 : 1, idle ? 0.0 : ex.bids[i].ready_time, ex.bids[i].t_d, i);
  };
  std::stable_sort(ranked.begin(), ranked.end(),
                   [&](std::size_t a, std::size_t b) { return key(a) < key(b); });
  const std::size_t team = static_cast<std::size_t>(order.team_size());
  if (ranked.size() < team) {
    return Unreachable("order " + order.id + ": needs " + std::to_string(team) +
                       " robot(s) that reach the first pick '" + state.map().point(first).name +
                       "', " + std::to_string(ranked.size()) + " can");
  }
  Status s = order.formation
                 ? state.AssignFormation({ranked[0], ranked[1], ranked[2]}, order.id, *task)
                 : state.AssignSingle(ranked[0], order.id, *task);
  if (!s.ok()) return s.error();
  char buf[64];
  for (std::size_t k = 0; k < team; ++k) {
    const Bid& b = ex.bids[ranked[k]];
    ex.winners.push_back(b.robot);
    const bool idle = state.queue(ranked[k]).size() == 1;  // the award just made
    std::snprintf(buf, sizeof(buf), idle ? "%.2f s away, idle" : "%.2f s away, free at %.2f s",
                  b.t_d, b.ready_time);
    ex.reason += (k == 0 ? "" : ", ") + b.robot + " (" + buf + ")";
  }
  ex.reason = "nearest idle robot first, else earliest free: " + ex.reason;
  return ex;
}

}  // namespace dispatch::engine
