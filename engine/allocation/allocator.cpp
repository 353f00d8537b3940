#include "engine/allocation/allocator.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <tuple>
#include <utility>

namespace dispatch::engine {

Result<PlanTask> PrepareOrder(const Order& order, const FleetState& state) {
  const std::string what = "order " + order.id + ": ";
  if (order.picks.empty()) return InvalidArgument(what + "no pick points");
  const WarehouseMap& map = state.map();
  auto known = [&](PointId p) { return p >= 0 && static_cast<std::size_t>(p) < map.point_count(); };
  for (std::size_t k = 0; k < order.picks.size(); ++k) {
    if (!known(order.picks[k])) {
      return NotFound(what + "pick " + std::to_string(k + 1) + " is an unknown point id " +
                      std::to_string(order.picks[k]));
    }
  }
  if (!known(order.drop)) {
    return NotFound(what + "drop is an unknown point id " + std::to_string(order.drop));
  }
  PlanTask task = state.TaskOf(order.picks, order.drop, order.work_time);
  task.stop_headings = order.stop_headings;
  if (!std::isfinite(task.work_time) || task.work_time < 0.0) {
    return InvalidArgument(what + "work time must be finite and >= 0 s, got " +
                           std::to_string(task.work_time));
  }
  if (order.formation && state.robot_count() < static_cast<std::size_t>(kFormationTeamSize)) {
    return Error{ErrorCode::kFailedPrecondition,
                 what + "a formation needs " + std::to_string(kFormationTeamSize) +
                     " robots, the fleet has " + std::to_string(state.robot_count())};
  }
  if (!task.stop_headings.empty()) {
    bool any = false;
    for (std::size_t i = 0; i < state.robot_count() && !any; ++i) any = state.CanServe(i, task);
    if (!any) {
      return Error{ErrorCode::kFailedPrecondition,
                   what + "a stop asks for a heading, and no robot can be planned into it (a four-wheel-steer robot, "
                          "planned through the map's free-space regions)"};
    }
  }
  const RouteTable& routes = state.routes();
  auto name = [&](PointId p) { return "'" + map.point(p).name + "'"; };
  for (std::size_t k = 0; k + 1 < task.picks.size(); ++k) {
    if (!std::isfinite(routes.Cost(task.picks[k], task.picks[k + 1]))) {
      return Unreachable(what + "pick " + std::to_string(k + 2) + " " + name(task.picks[k + 1]) +
                         " is unreachable from pick " + std::to_string(k + 1) + " " +
                         name(task.picks[k]));
    }
  }
  if (!std::isfinite(routes.Cost(task.picks.back(), task.drop))) {
    return Unreachable(what + "drop " + name(task.drop) + " is unreachable from the last pick " +
                       name(task.picks.back()));
  }
  return task;
}

std::vector<OrderAllocation> AllocateAll(Allocator& allocator, std::vector<Order> orders,
                                         FleetState& state) {
  std::stable_sort(orders.begin(), orders.end(), [](const Order& a, const Order& b) {
    return std::make_tuple(-a.priority, a.created_time, std::cref(a.id)) <
           std::make_tuple(-b.priority, b.created_time, std::cref(b.id));
  });
  std::vector<const Order*> batch;
  for (const Order& o : orders) batch.push_back(&o);
  std::vector<OrderAllocation> out;
  out.reserve(orders.size());
  allocator.AllocateBatch(batch, state, [&](const Order& o, Result<AwardExplanation> award) {
    out.push_back({o.id, std::move(award)});
  });
  return out;
}

void Allocator::AllocateBatch(const std::vector<const Order*>& orders, FleetState& state,
                              const AwardSink& sink) {
  for (const Order* o : orders) sink(*o, Allocate(*o, state));
}

}  // namespace dispatch::engine
