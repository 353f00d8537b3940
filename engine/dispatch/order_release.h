// Taking orders back from robots (issue 15 §1): a cancel, a failure, a lost or blocked robot.
// The orders leave their robots' plans (CutPlan); orders queued behind them on the same robots
// leave too and go back to `accepted` for re-allocation (one that has somehow started fails
// instead: its load is on a robot that is not going to deliver it in order).
//
// Pure: PlanRelease reads the book through lookups and returns what to change; the owner
// stores the change (one transaction) and then applies it. Thread-safe if the lookups are.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "engine/dispatch/assignment.h"
#include "engine/fleet/order.h"

namespace dispatch::engine {

struct ReleaseLookups {
  // The order's current state (nullopt: unknown order) and the robots it is assigned to.
  std::function<std::optional<OrderState>(const std::string& order_id)> state;
  std::function<std::vector<std::string>(const std::string& order_id)> robots;
  // The robot's plan (null: no robot or no plan).
  std::function<const Assignment*(const std::string& robot_id)> assignment;
};

struct OrderRelease {
  std::map<std::string, OrderState> to;                     // order -> new state
  std::map<std::string, Assignment> plans;                  // robot -> its plan without them
  std::map<std::string, std::vector<std::string>> removed;  // robot -> orders taken away
};

// `target(order_id)` is the new state of each of `order_ids` (cancelled, failed, or accepted
// for re-allocation); unknown orders are skipped.
OrderRelease PlanRelease(const std::vector<std::string>& order_ids,
                         const std::function<OrderState(const std::string& order_id)>& target,
                         const ReleaseLookups& book);

// The state a lost or blocked robot's order goes to: started ones fail (the load is on the
// robot), the others go back to accepted for another robot.
OrderState StateAfterRobotLoss(OrderState state);

}  // namespace dispatch::engine
