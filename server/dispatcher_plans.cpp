// Dispatcher: robot plans (one segment per order after an anchor waypoint), and taking
// orders back from robots (cancel, re-allocation).
#include <spdlog/spdlog.h>

#include <algorithm>

#include "engine/dispatch/order_release.h"
#include "server/dispatcher.h"

namespace dispatch::server {

Dispatcher::RobotRuntime* Dispatcher::RobotOf(const std::string& id) {
  auto it = robots_.find(id);
  return it == robots_.end() ? nullptr : &it->second;
}

OrderRoutes Dispatcher::RoutesOf(const std::string& order_id) const {
  OrderRoutes out;
  auto view = Find(order_id);
  if (!view) return out;
  for (const auto& robot_id : view->record.robots) {
    auto it = robots_.find(robot_id);
    if (it == robots_.end() || !it->second.has_assignment) continue;
    const RobotRuntime& r = it->second;
    const auto& a = r.assignment;
    const std::uint64_t released = ReleasedUpTo(r);
    auto& route = out[robot_id];
    const std::vector<std::string> order_of = engine::OrdersOfWaypoints(a);
    for (std::size_t i = 0; i < a.plan.waypoints.size(); ++i) {
      const auto& w = a.plan.waypoints[i];
      const auto seq = static_cast<std::uint64_t>(w.seq);
      if (order_of[i] == order_id && seq > r.progress.last_reached) route.push_back({seq, w.xy, w.action, seq <= released});
    }
  }
  return out;
}

RobotOutbound Dispatcher::PlanMessage(const RobotRuntime& robot, bool full,
                                      std::uint64_t from_sequence) const {
  RobotOutbound m;
  m.kind = full ? RobotOutbound::Kind::kAssignment : RobotOutbound::Kind::kPlanUpdate;
  const auto& a = robot.assignment;
  m.plan_id = a.plan_id;
  m.from_sequence = from_sequence;
  m.order_ids = a.order_ids;
  // Released: what the traffic gate has released so far (everything without traffic control).
  const std::uint64_t released = ReleasedUpTo(robot);
  const std::vector<std::string> order_of = engine::OrdersOfWaypoints(a);
  for (std::size_t i = 0; i < a.plan.waypoints.size(); ++i) {
    const auto& w = a.plan.waypoints[i];
    if (!full && static_cast<std::uint64_t>(w.seq) < from_sequence) continue;
    m.waypoints.push_back({w, order_of[i], static_cast<std::uint64_t>(w.seq) <= released});
  }
  m.released_up_to = released;
  for (const auto& id : a.order_ids) {
    auto view = Find(id);
    if (view && view->record.order.formation) {
      m.formation_members = view->record.robots;
      break;
    }
  }
  return m;
}

void Dispatcher::SendTo(RobotRuntime& robot, RobotOutbound message) {
  message.sequence = robot.record.next_sequence++;
  message.server_time = Now();
  if (robot.link) {
    // A Welcome waits for the snapshot that holds the robot; plans, grants and holds do not.
    const bool after_publish = message.kind == RobotOutbound::Kind::kWelcome;
    Defer([link = robot.link, message = std::move(message)]() mutable { link->Send(std::move(message)); },
          after_publish);
  }
}

bool Dispatcher::ReleaseOrders(const std::vector<std::string>& order_ids,
                               const std::function<engine::OrderState(const OrderView&)>& target,
                               const std::string& reason, ServiceStatus* status) {
  const double now = Now();
  engine::ReleaseLookups book;
  book.state = [this](const std::string& id) -> std::optional<engine::OrderState> {
    auto view = Find(id);
    return view ? std::optional<engine::OrderState>(view->record.order.state) : std::nullopt;
  };
  book.robots = [this](const std::string& id) {
    auto view = Find(id);
    return view ? view->record.robots : std::vector<std::string>{};
  };
  book.assignment = [this](const std::string& robot_id) -> const storage::AssignmentRecord* {
    RobotRuntime* r = RobotOf(robot_id);
    return r && r->has_assignment ? &r->assignment : nullptr;
  };
  engine::OrderRelease release = engine::PlanRelease(
      order_ids, [&](const std::string& id) { return target(*Find(id)); }, book);
  auto& to = release.to;
  auto& plans = release.plans;
  auto& removed = release.removed;
  std::vector<storage::OrderEvent> events;
  auto committed = store_.RunInTransaction([&](storage::Store& s) -> engine::Status {
    events.clear();
    for (const auto& [id, state] : to) {
      auto view = Find(id);
      if (!view || view->record.order.state == state) continue;
      storage::OrderTransition t;
      t.order_id = id;
      t.to = state;
      t.time = now;
      if (state == engine::OrderState::kAccepted) t.robots = std::vector<std::string>{};
      t.detail = state == engine::OrderState::kAccepted ? "re-allocated: " + reason : reason;
      auto e = s.TransitionOrder(t);
      if (!e.ok()) return e.error();
      events.push_back(*e);
    }
    for (auto& [robot_id, plan] : plans) {
      plan.updated_time = now;
      if (auto saved = s.SaveAssignment(plan); !saved.ok()) return saved.error();
      storage::RobotRecord rec = robots_.at(robot_id).record;
      rec.robot.task_queue = plan.order_ids;
      rec.next_sequence += 1;  // the Cancel below
      if (auto saved = s.UpsertRobot(rec); !saved.ok()) return saved.error();
    }
    return engine::Ok{};
  });
  if (!committed.ok()) {
    *status = FromEngineError(committed.error());
    spdlog::error("releasing orders failed, nothing changed: {}", committed.error().message);
    return false;
  }
  for (const auto& [id, state] : to) {
    auto view = std::make_shared<OrderView>(*Find(id));
    if (view->record.order.state == state) continue;
    view->record.order.state = state;
    view->record.updated_time = now;
    if (state == engine::OrderState::kAccepted) {
      view->record.robots.clear();
    } else {
      view->record.reason = reason;
      view->finished_time = now;
    }
    Put(view);
    if (state != engine::OrderState::kAccepted) order_distance_.erase(id);  // finished: nothing more driven
  }
  for (const auto& e : events) Journal(e);
  for (auto& [robot_id, plan] : plans) {
    RobotRuntime& r = robots_.at(robot_id);
    r.assignment = std::move(plan);
    r.record.robot.task_queue = r.assignment.order_ids;
    RobotOutbound cancel;
    cancel.kind = RobotOutbound::Kind::kCancel;
    cancel.order_ids = removed[robot_id];
    cancel.reason = reason;
    SendTo(r, std::move(cancel));
    SyncGate(r);
  }
  dirty_ = true;
  return true;
}

}  // namespace dispatch::server
