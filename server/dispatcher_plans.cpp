// Dispatcher: allocation rounds, robot plans (one segment per order after an anchor
// waypoint), and taking orders back from robots (cancel, re-allocation).
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <set>

#include "server/dispatcher.h"
#include "server/json_convert.h"

namespace dispatch::server {
namespace {

// "R2" < "R10": letters compare as text, digit runs as numbers.
bool NaturalLess(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit(static_cast<unsigned char>(a[i])) && std::isdigit(static_cast<unsigned char>(b[j]))) {
      std::size_t ie = i, je = j;
      while (ie < a.size() && std::isdigit(static_cast<unsigned char>(a[ie]))) ++ie;
      while (je < b.size() && std::isdigit(static_cast<unsigned char>(b[je]))) ++je;
      const std::string na = a.substr(i, ie - i), nb = b.substr(j, je - j);
      if (na.size() != nb.size()) return na.size() < nb.size();
      if (na != nb) return na < nb;
      i = ie;
      j = je;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

bool HasOrders(const storage::AssignmentRecord& a, bool has) { return has && !a.order_ids.empty(); }

}  // namespace

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

void Dispatcher::AllocatePending() {
  retry_allocation_ = false;
  allocation_due_ = false;
  std::vector<std::shared_ptr<const OrderView>> pending;
  for (const auto& view : orders_) {
    if (view->record.order.state == engine::OrderState::kAccepted) pending.push_back(view);
  }
  if (pending.empty()) return;
  std::vector<std::string> ids;
  for (const auto& [id, r] : robots_) {
    if (r.link && r.record.robot.current_point != engine::kNoPoint &&
        r.record.robot.state != engine::RobotState::kFault && (!gate_ || gate_->Available(id))) {
      ids.push_back(id);
    }
  }
  if (ids.empty()) return;
  std::sort(ids.begin(), ids.end(), NaturalLess);
  std::sort(pending.begin(), pending.end(), [](const auto& a, const auto& b) {
    const auto& x = a->record.order;
    const auto& y = b->record.order;
    if (x.priority != y.priority) return x.priority > y.priority;
    if (x.created_time != y.created_time) return x.created_time < y.created_time;
    return a->position < b->position;
  });
  const double now = Now();
  std::vector<engine::FleetRobot> fleet_robots;
  for (const auto& id : ids) {
    const RobotRuntime& r = robots_.at(id);
    engine::FleetRobot f;
    f.id = id;
    f.start = r.record.robot.current_point;
    if (gate_ && !HasOrders(r.assignment, r.has_assignment)) {
      // A new plan starts where the traffic controller has the robot (standing or arriving).
      if (const engine::PointId p = gate_->StartPoint(id); p != engine::kNoPoint) f.start = p;
    }
    f.ready_time = now;
    fleet_robots.push_back(f);
  }
  auto fleet = engine::FleetState::Create(map_, routes_, fleet_robots, options_.allocation,
                                          zone_index_);
  if (!fleet.ok()) {
    spdlog::error("allocation: {}", fleet.error().message);
    return;
  }
  engine::FleetState state = std::move(fleet).value();
  zone_index_ = state.zone_index();  // one floor, one index: the next round skips the grid
  for (std::size_t i = 0; i < ids.size(); ++i) ReplayQueue(state, i, robots_.at(ids[i]));
  for (const auto& view : pending) {
    const engine::Order& order = view->record.order;
    if (static_cast<std::size_t>(order.team_size()) > ids.size()) continue;
    const auto start = Clock::now();
    const bool stored = AwardOrder(order, state);
    if (options_.metrics) {
      options_.metrics->ObserveAllocation(std::chrono::duration<double>(Clock::now() - start).count());
    }
    if (!stored) {
      retry_allocation_ = true;  // the store failed: try again on the next tick
      return;
    }
  }
}

void Dispatcher::ReplayQueue(engine::FleetState& fleet, std::size_t index, const RobotRuntime& r) const {
  if (!HasOrders(r.assignment, r.has_assignment)) return;
  const auto& plan = r.assignment;
  for (std::size_t k = 0; k < plan.order_ids.size(); ++k) {
    auto view = Find(plan.order_ids[k]);
    if (!view) return;
    const engine::Order& order = view->record.order;
    std::vector<engine::PointId> picks = order.picks;
    if (k == 0) {  // only the picks still ahead of the robot
      picks.clear();
      for (std::size_t w = 1; w < SegmentStart(plan, 1) && w < plan.plan.waypoints.size(); ++w) {
        const auto& wp = plan.plan.waypoints[w];
        if (wp.action == engine::WaypointAction::kPick && static_cast<std::uint64_t>(wp.seq) > r.last_reached) {
          picks.push_back(wp.point);
        }
      }
      if (picks.empty()) picks.push_back(order.drop);  // picked: only the drop is left
    }
    // The stored waypoints of this order (the first: those not reached yet), re-timed from
    // the queue's end: no routing (on a large floor every random pick is a new destination
    // of the lazy route table, and re-routing every queue each round thrashed its cache).
    const std::size_t begin = k == 0 ? 1 : SegmentStart(plan, k), end = SegmentStart(plan, k + 1);
    std::vector<engine::Waypoint> segment;
    const engine::PointId from = fleet.summary(index).end_point;
    segment.push_back({0, from, map_->point(from).position, 0.0, engine::WaypointAction::kMove, 0.0});
    for (std::size_t w = begin; w < end && w < plan.plan.waypoints.size(); ++w) {
      engine::Waypoint wp = plan.plan.waypoints[w];
      if (k == 0 && static_cast<std::uint64_t>(wp.seq) <= r.last_reached) continue;
      if (segment.size() == 1) {
        // Reach the first one from the queue's end at cruise speed, then keep the plan's pace.
        const double lead = (wp.xy - segment.front().xy).norm() / options_.allocation.speed;
        segment.front().eta = wp.eta - lead;
      }
      segment.push_back(wp);
    }
    const engine::PlanTask task = fleet.TaskOf(picks, order.drop, order.work_time);
    engine::Status assigned = engine::InvalidArgument("no stored waypoints");
    if (segment.size() >= 2) assigned = fleet.AssignPlanned(index, order.id, task, std::move(segment));
    if (!assigned.ok()) assigned = fleet.AssignSingle(index, order.id, task);
    if (!assigned.ok()) {
      spdlog::warn("allocation: queue of {} replayed up to {} only: {}", r.record.robot.id, order.id,
                   assigned.error().message);
      return;
    }
  }
}

bool Dispatcher::AwardOrder(const engine::Order& order, engine::FleetState& fleet) {
  std::vector<std::size_t> old_sizes;
  for (std::size_t i = 0; i < fleet.robot_count(); ++i) old_sizes.push_back(fleet.plan(i).waypoints.size());
  auto award = allocator_->Allocate(order, fleet);
  if (!award.ok()) {
    spdlog::warn("order {} not allocated (stays accepted): {}", order.id, award.error().message);
    return true;
  }
  const double now = Now();
  struct Change {
    RobotRuntime* robot;
    storage::AssignmentRecord assignment;
    storage::RobotRecord record;
    bool fresh;
    std::uint64_t first_new;
  };
  std::vector<Change> changes;
  for (const auto& w : award->winners) {
    const std::size_t i = *fleet.FindRobot(w);
    RobotRuntime& r = robots_.at(w);
    Change c{&r, r.assignment, r.record, !HasOrders(r.assignment, r.has_assignment), 0};
    std::int64_t next_seq = c.assignment.released_up_to + 1;
    if (!c.assignment.plan.waypoints.empty()) {
      next_seq = std::max<std::int64_t>(next_seq, c.assignment.plan.waypoints.back().seq + 1);
    }
    const auto& fp = fleet.plan(i).waypoints;
    std::size_t from = old_sizes[i];
    if (c.fresh) {
      c.assignment.robot_id = w;
      c.assignment.plan_id += 1;
      c.assignment.plan.robot_id = w;
      c.assignment.plan.waypoints.clear();
      c.assignment.order_ids.clear();
      from = 0;
    }
    c.first_new = static_cast<std::uint64_t>(next_seq);
    // The replayed queue (see ReplayQueue) re-times the robot's remaining work from now; the
    // new segment never starts before the robot's actual plan ends.
    const double shift = c.fresh || from >= fp.size()
                             ? 0.0
                             : std::max(0.0, c.assignment.plan.end_time() - fp[from - 1].departure());
    for (std::size_t k = from; k < fp.size(); ++k) {
      engine::Waypoint wp = fp[k];
      wp.seq = static_cast<int>(next_seq++);
      wp.eta += shift;
      c.assignment.plan.waypoints.push_back(wp);
    }
    c.assignment.order_ids.push_back(order.id);
    c.assignment.released_up_to = next_seq - 1;
    c.assignment.updated_time = now;
    c.record.robot.task_queue = c.assignment.order_ids;
    c.record.next_sequence += 1;  // the Assignment / PlanUpdate below
    changes.push_back(std::move(c));
  }
  const AllocationRecord allocation{*award, options_.allocation.alpha, options_.allocation.beta,
                                    options_.allocation.zeta, now};
  std::vector<storage::OrderEvent> events;
  auto committed = store_.RunInTransaction([&](storage::Store& s) -> engine::Status {
    events.clear();
    storage::OrderTransition t;
    t.order_id = order.id;
    t.to = engine::OrderState::kAssigned;
    t.time = now;
    t.robots = award->winners;
    t.detail = award->reason;
    auto e1 = s.TransitionOrder(t);
    if (!e1.ok()) return e1.error();
    events.push_back(*e1);
    auto e2 = s.AppendProgress(order.id, now, AllocationDetail(allocation));
    if (!e2.ok()) return e2.error();
    events.push_back(*e2);
    for (const auto& c : changes) {
      if (auto saved = s.SaveAssignment(c.assignment); !saved.ok()) return saved.error();
      if (auto saved = s.UpsertRobot(c.record); !saved.ok()) return saved.error();
    }
    return engine::Ok{};
  });
  if (!committed.ok()) {
    spdlog::error("award of order {} not stored (order stays accepted): {}", order.id,
                  committed.error().message);
    return false;
  }
  auto view = std::make_shared<OrderView>(*Find(order.id));
  view->record.order.state = engine::OrderState::kAssigned;
  view->record.robots = award->winners;
  view->record.updated_time = now;
  view->explanation = allocation;
  Put(view);
  for (const auto& e : events) Journal(e);
  for (auto& c : changes) {
    RobotRuntime& r = *c.robot;
    r.assignment = std::move(c.assignment);
    r.has_assignment = true;
    r.record.robot.task_queue = r.assignment.order_ids;
  }
  // The gate learns every member's plan before any is sent (a formation needs all three).
  for (auto& c : changes) SyncGate(*c.robot);
  for (auto& c : changes) SendTo(*c.robot, PlanMessage(*c.robot, c.fresh, c.first_new));
  spdlog::info("order {} assigned: {}", order.id, award->reason);
  dirty_ = true;
  return true;
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
