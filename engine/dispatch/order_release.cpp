#include "engine/dispatch/order_release.h"

#include <algorithm>

namespace dispatch::engine {

OrderRelease PlanRelease(const std::vector<std::string>& order_ids,
                         const std::function<OrderState(const std::string& order_id)>& target,
                         const ReleaseLookups& book) {
  OrderRelease out;
  for (const auto& id : order_ids) {
    if (book.state(id)) out.to[id] = target(id);
  }
  std::vector<std::string> work = order_ids;
  while (!work.empty()) {
    const std::string id = work.back();
    work.pop_back();
    if (!book.state(id)) continue;
    for (const auto& robot_id : book.robots(id)) {
      const Assignment* current = book.assignment(robot_id);
      if (!current) continue;
      Assignment& plan = out.plans.try_emplace(robot_id, *current).first->second;
      if (std::find(plan.order_ids.begin(), plan.order_ids.end(), id) == plan.order_ids.end()) continue;
      const std::vector<std::string> later = CutPlan(plan, id);
      auto& removed = out.removed[robot_id];
      removed.push_back(id);
      for (const auto& l : later) {
        removed.push_back(l);
        if (out.to.count(l)) continue;
        // A later order cannot have started; if it somehow has, it fails rather than vanish.
        const std::optional<OrderState> s = book.state(l);
        out.to[l] = s && *s == OrderState::kInProgress ? OrderState::kFailed : OrderState::kAccepted;
        work.push_back(l);
      }
    }
  }
  return out;
}

OrderState StateAfterRobotLoss(OrderState state) {
  return state == OrderState::kInProgress ? OrderState::kFailed : OrderState::kAccepted;
}

}  // namespace dispatch::engine
