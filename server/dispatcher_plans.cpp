// Dispatcher: robot plans (one segment per order after an anchor waypoint), and taking
// orders back from robots (cancel, re-allocation).
#include <spdlog/spdlog.h>

#include <algorithm>

#include "server/dispatcher.h"

namespace dispatch::server {

Dispatcher::RobotRuntime* Dispatcher::RobotOf(const std::string& id) {
  auto it = robots_.find(id);
  return it == robots_.end() ? nullptr : &it->second;
}

std::size_t Dispatcher::SegmentStart(const storage::AssignmentRecord& plan, std::size_t k) {
  if (k == 0) return 1;
  std::size_t drops = 0;
  for (std::size_t i = 1; i < plan.plan.waypoints.size(); ++i) {
    if (plan.plan.waypoints[i].action == engine::WaypointAction::kDrop && ++drops == k) return i + 1;
  }
  return plan.plan.waypoints.size();
}

std::vector<std::string> Dispatcher::OrdersOfWaypoints(const storage::AssignmentRecord& plan) {
  // Waypoint 0 anchors; then segment k (up to and including its drop) serves order_ids[k].
  const auto& w = plan.plan.waypoints;
  std::vector<std::string> out(w.size());
  std::size_t drops = 0;
  for (std::size_t i = 1; i < w.size() && drops < plan.order_ids.size(); ++i) {
    out[i] = plan.order_ids[drops];
    if (w[i].action == engine::WaypointAction::kDrop) ++drops;
  }
  return out;
}

std::string Dispatcher::OrderOfWaypoint(const storage::AssignmentRecord& plan, std::size_t index) {
  if (index == 0) return {};
  std::size_t drops = 0;
  for (std::size_t i = 1; i < index && i < plan.plan.waypoints.size(); ++i) {
    if (plan.plan.waypoints[i].action == engine::WaypointAction::kDrop) ++drops;
  }
  return drops < plan.order_ids.size() ? plan.order_ids[drops] : std::string();
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
    const std::vector<std::string> order_of = OrdersOfWaypoints(a);
    for (std::size_t i = 0; i < a.plan.waypoints.size(); ++i) {
      const auto& w = a.plan.waypoints[i];
      const auto seq = static_cast<std::uint64_t>(w.seq);
      if (order_of[i] == order_id && seq > r.last_reached) route.push_back({seq, w.xy, w.action, seq <= released});
    }
  }
  return out;
}

std::vector<std::string> Dispatcher::CutPlan(storage::AssignmentRecord& plan,
                                             const std::string& order_id) {
  auto it = std::find(plan.order_ids.begin(), plan.order_ids.end(), order_id);
  if (it == plan.order_ids.end()) return {};
  const auto k = static_cast<std::size_t>(it - plan.order_ids.begin());
  plan.plan.waypoints.resize(std::max<std::size_t>(1, SegmentStart(plan, k)));
  std::vector<std::string> later(it + 1, plan.order_ids.end());
  plan.order_ids.resize(k);
  return later;
}

bool Dispatcher::TrimDone(storage::AssignmentRecord& plan, const std::string& order_id) {
  if (plan.order_ids.empty() || plan.order_ids.front() != order_id) return false;
  const std::size_t drop = SegmentStart(plan, 1) - 1;  // the first order's drop waypoint
  auto& w = plan.plan.waypoints;
  w.erase(w.begin(), w.begin() + static_cast<std::ptrdiff_t>(std::min(drop, w.size() - 1)));
  plan.order_ids.erase(plan.order_ids.begin());
  return true;
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
  const std::vector<std::string> order_of = OrdersOfWaypoints(a);
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
  std::map<std::string, engine::OrderState> to;             // order -> new state
  std::map<std::string, storage::AssignmentRecord> plans;   // robot -> new plan
  std::map<std::string, std::vector<std::string>> removed;  // robot -> orders taken away
  std::vector<std::string> work = order_ids;
  for (const auto& id : order_ids) {
    if (auto v = Find(id)) to[id] = target(*v);
  }
  while (!work.empty()) {
    const std::string id = work.back();
    work.pop_back();
    auto view = Find(id);
    if (!view) continue;
    for (const auto& robot_id : view->record.robots) {
      RobotRuntime* r = RobotOf(robot_id);
      if (!r || !r->has_assignment) continue;
      auto [it, inserted] = plans.try_emplace(robot_id, r->assignment);
      auto& plan = it->second;
      if (std::find(plan.order_ids.begin(), plan.order_ids.end(), id) == plan.order_ids.end()) continue;
      auto later = CutPlan(plan, id);
      removed[robot_id].push_back(id);
      for (const auto& l : later) {
        removed[robot_id].push_back(l);
        if (to.count(l)) continue;
        auto lv = Find(l);
        // A later order cannot have started; if it somehow has, it fails rather than vanish.
        to[l] = lv && lv->record.order.state == engine::OrderState::kInProgress
                    ? engine::OrderState::kFailed
                    : engine::OrderState::kAccepted;
        work.push_back(l);
      }
    }
  }
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
