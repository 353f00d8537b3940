#include "engine/allocation/exact_allocator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <set>
#include <string>
#include <utility>

#include "engine/allocation/batch_orders.h"
#include "engine/planning/plan_limits.h"

namespace dispatch::engine {
namespace {

// The free queue places of `robots` (AllocationConfig::max_queue; unbounded without a limit).
std::size_t FreePlaces(const FleetState& state, const std::set<std::size_t>& robots) {
  const std::size_t max_queue = state.config().max_queue;
  if (max_queue == 0) return std::numeric_limits<std::size_t>::max();
  std::size_t free = 0;
  for (std::size_t r : robots) free += max_queue - std::min(max_queue, state.queue(r).size());
  return free;
}

// robots ^ orders, saturating at well above any limit.
double MapCount(std::size_t robots, std::size_t orders) {
  return std::pow(static_cast<double>(robots), static_cast<double>(orders));
}

}  // namespace

ExactAllocator::ExactAllocator(ExactOptions options) : options_(options) {
  options_.candidates = std::max<std::size_t>(1, options_.candidates);
  options_.max_maps = std::max(options_.max_maps, options_.candidates);
}

Result<AwardExplanation> ExactAllocator::Allocate(const Order& order, FleetState& state) {
  return AllocateAsBatch(*this, order, state);
}

void ExactAllocator::AllocateBatch(const std::vector<const Order*>& orders, FleetState& state,
                                   const AwardSink& sink) {
  BatchSingles taken = TakeSingles(orders, state, auction_, sink);
  const std::vector<const Order*>& singles = taken.orders;
  const std::vector<PlanTask>& tasks = taken.tasks;
  if (state.config().max_queue == 1) {
    std::vector<std::size_t> robots;
    for (std::size_t r = 0; r < state.robot_count(); ++r) {
      if (state.HasRoom(r)) robots.push_back(r);
    }
    const double small = static_cast<double>(std::min(robots.size(), singles.size()));
    const double large = static_cast<double>(std::max(robots.size(), singles.size()));
    if (small * small * large <= options_.max_one_to_one_work) {
      AllocateOneToOne(singles, tasks, robots, state, sink);
      return;
    }
  }
  const std::function<bool()> stop = DeadlineCheck(options_.budget);
  std::size_t next = 0;
  while (next < singles.size()) {
    if (stop()) {  // the budget is spent: the rest one at a time
      for (; next < singles.size(); ++next) sink(*singles[next], auction_.Allocate(*singles[next], state));
      return;
    }
    // The next chunk: orders in batch order while robots ^ orders stays within max_maps.
    std::vector<std::size_t> chunk;
    std::set<std::size_t> robots;
    while (next < singles.size()) {
      const std::vector<std::size_t> mine = SoonestRobots(state, tasks[next], options_.candidates);
      if (mine.empty()) {  // no robot with room reaches it: the auction says why
        if (!chunk.empty()) break;  // after the chunk is committed (its robots may fill up)
        sink(*singles[next], auction_.Allocate(*singles[next], state));
        ++next;
        continue;
      }
      std::set<std::size_t> merged = robots;
      merged.insert(mine.begin(), mine.end());
      if (!chunk.empty() && (MapCount(merged.size(), chunk.size() + 1) > static_cast<double>(options_.max_maps) ||
                             FreePlaces(state, merged) < chunk.size() + 1)) {
        break;
      }
      robots = std::move(merged);
      chunk.push_back(next++);
    }
    if (chunk.empty()) continue;

    std::vector<Order> batch;
    for (std::size_t k : chunk) batch.push_back(*singles[k]);
    OptimalAssignmentOptions search;
    search.objective = options_.objective;
    search.robots.assign(robots.begin(), robots.end());
    search.respect_queue_room = true;
    search.max_maps = options_.max_maps;
    search.stop = stop;
    Result<BatchAssignment> best = BruteForceAssignment(state, batch, search);
    if (!best.ok()) {  // no finite map, or the budget ran out: the auction, order by order
      for (std::size_t k : chunk) sink(*singles[k], auction_.Allocate(*singles[k], state));
      continue;
    }
    char what[96];
    std::snprintf(what, sizeof(what), "exact over %zu orders and %zu robots", chunk.size(), robots.size());
    for (std::size_t c = 0; c < chunk.size(); ++c) {
      Commit(*singles[chunk[c]], tasks[chunk[c]], best->robot_of_order[c], what, best->cost, state, sink);
    }
  }
}

void ExactAllocator::Commit(const Order& order, const PlanTask& task, std::size_t robot, const char* what,
                            double batch_cost, FleetState& state, const AwardSink& sink) const {
  const QueueSummary before = state.summary(robot);
  if (Status s = state.AssignSingle(robot, order.id, task); !s.ok()) {
    sink(order, s.error());
    return;
  }
  AwardExplanation ex;
  ex.order_id = order.id;
  ex.strategy = std::string(name());
  // The winner's terms as the auction would state them (its queue up to this order).
  const QueueSummary& after = state.summary(robot);
  Bid bid;
  bid.robot = state.robot_id(robot);
  bid.ready_time = before.end_time;
  bid.t_d = after.travel_time;
  bid.t_w = after.work_time;
  bid.t_t = bid.t_d + bid.t_w;
  bid.bid = BidValue(state.config().alpha, state.config().beta, bid.t_t, bid.t_d, 0.0);
  ex.bids.push_back(bid);
  ex.winners.push_back(bid.robot);
  char buf[200];
  std::snprintf(buf, sizeof(buf), "%s: %s (B=%.2f; %s %.2f)", what, bid.robot.c_str(), bid.bid,
                options_.objective == BatchObjective::kBidSum ? "bid sum" : "queue totals", batch_cost);
  ex.reason = buf;
  sink(order, std::move(ex));
}

void ExactAllocator::AllocateOneToOne(const std::vector<const Order*>& singles, const std::vector<PlanTask>& tasks,
                                      const std::vector<std::size_t>& robots, FleetState& state,
                                      const AwardSink& sink) {
  std::vector<Order> batch;
  for (const Order* order : singles) batch.push_back(*order);
  Result<BatchAssignment> best = OneToOneAssignment(state, batch, robots);
  if (robots.empty() || !best.ok()) {  // the auction says why
    for (const Order* order : singles) sink(*order, auction_.Allocate(*order, state));
    return;
  }
  char what[96];
  std::snprintf(what, sizeof(what), "one-to-one over %zu orders and %zu robots", singles.size(), robots.size());
  for (std::size_t k = 0; k < singles.size(); ++k) {
    const std::size_t robot = best->robot_of_order[k];
    if (robot != kNoRobot) {
      Commit(*singles[k], tasks[k], robot, what, best->cost, state, sink);
    } else {
      sink(*singles[k], Error{ErrorCode::kFailedPrecondition,
                              "order " + singles[k]->id + ": " + what +
                                  ", every robot with room took a cheaper order or cannot reach this one"});
    }
  }
}

}  // namespace dispatch::engine
