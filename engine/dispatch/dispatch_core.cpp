// DispatchCore: the book, orders, allocation rounds, applying changes and plan messages.
// Robots, their reports and traffic are in dispatch_core_robots.cpp.
#include "engine/dispatch/dispatch_core.h"

#include <algorithm>
#include <limits>

#include "engine/dispatch/order_release.h"

namespace dispatch::engine {

PlanExecution DefaultPlanExecution(PlannerKind planner) {
  return planner == PlannerKind::kRules ? PlanExecution::kTimes : PlanExecution::kClaim;
}

std::map<std::string, std::uint64_t> Change::MessageCounts() const {
  std::map<std::string, std::uint64_t> out;
  for (const PlanSend& s : sends) ++out[s.robot];
  return out;
}

Result<std::unique_ptr<DispatchCore>> DispatchCore::Create(std::shared_ptr<const WarehouseMap> map,
                                                           std::shared_ptr<const RouteTable> routes,
                                                           CoreOptions options) {
  if (!map || !routes) return InvalidArgument("dispatch core: null map or route table");
  std::unique_ptr<DispatchCore> core(new DispatchCore(std::move(map), std::move(routes), std::move(options)));
  if (core->options_.traffic_control) {
    if (auto valid = core->options_.traffic.Validate(); !valid.ok()) return valid.error();
    auto gate = TrafficGate::Create(core->map_, core->routes_, core->options_.traffic);
    if (!gate.ok()) return gate.error();
    core->gate_ = std::move(gate).value();
  }
  return core;
}

DispatchCore::DispatchCore(std::shared_ptr<const WarehouseMap> map, std::shared_ptr<const RouteTable> routes,
                           CoreOptions options)
    : map_(std::move(map)), routes_(std::move(routes)), options_(std::move(options)) {}

const BookOrder* DispatchCore::order(const std::string& id) const {
  auto it = orders_.find(id);
  return it == orders_.end() ? nullptr : &it->second;
}

const BookRobot* DispatchCore::robot(const std::string& id) const {
  auto it = robot_index_.find(id);
  return it == robot_index_.end() ? nullptr : it->second;
}

BookRobot* DispatchCore::FindRobot(const std::string& id) {
  auto it = robot_index_.find(id);
  return it == robot_index_.end() ? nullptr : it->second;
}

BookRobot& DispatchCore::Book(const std::string& id) {
  if (BookRobot* r = FindRobot(id)) return *r;
  const auto it = robots_.try_emplace(id).first;
  BookRobot& r = it->second;
  robot_index_.emplace(id, &r);
  const auto at = std::upper_bound(bidding_order_.begin(), bidding_order_.end(), id,
                                   [](const std::string& a, const auto& b) { return NaturalLess(a, *b.first); });
  bidding_order_.insert(at, {&it->first, &r});
  return r;
}

bool DispatchCore::TakeAllocationDue() {
  const bool due = allocation_due_;
  allocation_due_ = false;
  return due;
}

std::uint64_t DispatchCore::ReleasedUpTo(const std::string& id) const {
  if (gate_) return gate_->ReleasedUpTo(id);
  const BookRobot* r = robot(id);
  if (!r || r->assignment.plan.waypoints.empty()) return 0;
  return static_cast<std::uint64_t>(r->assignment.plan.waypoints.back().seq);
}

OrderRoutes DispatchCore::RoutesOf(const std::string& order_id) const {
  OrderRoutes out;
  const BookOrder* o = order(order_id);
  if (!o) return out;
  for (const auto& robot_id : o->robots) {
    const BookRobot* r = robot(robot_id);
    if (!r || !r->has_assignment) continue;
    const Assignment& a = r->assignment;
    const std::uint64_t released = ReleasedUpTo(robot_id);
    auto& route = out[robot_id];
    const std::vector<std::string> order_of = OrdersOfWaypoints(a);
    for (std::size_t i = 0; i < a.plan.waypoints.size(); ++i) {
      const Waypoint& w = a.plan.waypoints[i];
      const auto seq = static_cast<std::uint64_t>(w.seq);
      if (order_of[i] == order_id && seq > r->progress.last_reached) {
        route.push_back({seq, w.xy, w.action, seq <= released, w.heading, w.mode});
      }
    }
  }
  return out;
}

// --- Orders ------------------------------------------------------------------------------

void DispatchCore::AddOrder(Order order, std::vector<std::string> robots) {
  if (IsTerminal(order.state)) return;
  const std::string id = order.id;
  BookOrder& b = orders_[id];
  b.order = std::make_shared<const Order>(std::move(order));
  b.robots = std::move(robots);
  allocation_due_ = true;
}

Result<Change> DispatchCore::PlanCancel(const std::string& order_id, const std::string& reason, double now) {
  if (!order(order_id)) return NotFound("no open order with id '" + order_id + "'");
  return PlanReleaseOf({order_id}, [](OrderState) { return OrderState::kCancelled; }, reason, now);
}

Change DispatchCore::PlanLoss(const std::string& id, const std::string& why, double now) {
  const BookRobot* r = robot(id);
  if (!r || !r->has_assignment || r->assignment.order_ids.empty()) return Change{now, {}, {}, {}, {}, 0, {}};
  const std::string at = id + "@" + std::to_string(r->robot.current_point);
  const int max = options_.max_give_backs;
  Change c = PlanReleaseOf(r->assignment.order_ids, StateAfterRobotLoss, why, now);
  for (OrderChange& line : c.orders) {
    if (line.to != OrderState::kAccepted) continue;
    line.lost_at = at;
    const BookOrder* o = order(line.order_id);
    if (max <= 0 || o->lost_at != at || o->lost_there < max) continue;
    line.to = OrderState::kFailed;
    line.robots.reset();
    line.detail = why + " (given back " + std::to_string(o->lost_there) + " times in a row by " + id + " there)";
  }
  return c;
}

Change DispatchCore::PlanReleaseOf(const std::vector<std::string>& order_ids,
                                   const std::function<OrderState(OrderState)>& target,
                                   const std::string& reason, double now) const {
  ReleaseLookups book;
  book.state = [this](const std::string& id) -> std::optional<OrderState> {
    const BookOrder* o = order(id);
    return o ? std::optional<OrderState>(o->order->state) : std::nullopt;
  };
  book.robots = [this](const std::string& id) {
    const BookOrder* o = order(id);
    return o ? o->robots : std::vector<std::string>{};
  };
  book.assignment = [this](const std::string& robot_id) -> const Assignment* {
    const BookRobot* r = robot(robot_id);
    return r && r->has_assignment ? &r->assignment : nullptr;
  };
  OrderRelease release =
      PlanRelease(order_ids, [&](const std::string& id) { return target(order(id)->order->state); }, book);
  Change c;
  c.time = now;
  for (const auto& [id, state] : release.to) {
    if (order(id)->order->state == state) continue;
    OrderChange line;
    line.order_id = id;
    line.to = state;
    if (state == OrderState::kAccepted) line.robots = std::vector<std::string>{};
    line.detail = state == OrderState::kAccepted ? "re-allocated: " + reason : reason;
    c.orders.push_back(std::move(line));
  }
  for (auto& [robot_id, plan] : release.plans) {
    plan.updated_time = now;
    c.sends.push_back({robot_id, PlanSend::Kind::kCancel, 0, release.removed[robot_id], reason});
    c.plans.emplace(robot_id, std::move(plan));
  }
  return c;
}

std::optional<OrderChange> DispatchCore::StartLine(const std::string& order_id, const std::string& detail) const {
  const BookOrder* o = order(order_id);
  if (!o || o->order->state != OrderState::kAssigned) return std::nullopt;
  OrderChange line;
  line.order_id = order_id;
  line.to = OrderState::kInProgress;
  line.detail = detail;
  return line;
}

// --- Allocation rounds -------------------------------------------------------------------

bool DispatchCore::Eligible(const BookRobot& r) const {
  return r.connected && r.robot.current_point != kNoPoint && r.robot.state != RobotState::kFault &&
         r.marks.paused_by.empty() && r.marks.out_of_service_by.empty() && !OnTrip(r) &&
         (!gate_ || gate_->Available(r.robot.id));
}

PointId DispatchCore::StartOf(const BookRobot& r) const {
  // A new plan starts where the traffic controller has the robot (standing or arriving).
  const PointId p = gate_ ? gate_->StartPoint(r.robot.id) : kNoPoint;
  return p != kNoPoint ? p : r.robot.current_point;
}

RoundKey DispatchCore::KeyOf(const BookRobot& r) const {
  RoundKey key;
  key.plan_id = r.has_assignment ? r.assignment.plan_id : 0;
  if (r.has_assignment && !r.assignment.order_ids.empty()) {
    key.last_order = r.assignment.order_ids.back();  // new work starts at its queue's end
  } else {
    key.start = StartOf(r);
  }
  return key;
}

std::optional<RoundInput> DispatchCore::MakeRound(double now, RoundCommit& commit) const {
  RoundInput input;
  input.now = now;
  for (const auto& [id, o] : orders_) {
    if (o.order->state == OrderState::kAccepted) input.pending.push_back(o.order);
  }
  if (input.pending.empty()) return std::nullopt;
  std::vector<std::pair<const std::string*, const BookRobot*>> bidders;  // in bidding order
  for (const auto& [id, r] : bidding_order_) {
    if (Eligible(*r)) bidders.emplace_back(id, r);
  }
  if (bidders.empty()) return std::nullopt;
  std::sort(input.pending.begin(), input.pending.end(),
            [](const auto& a, const auto& b) { return AllocationOrderLess(*a, *b); });
  if (options_.one_formation_per_pick) {
    // One formation at a time on its way to a first pick: teams converging on one pick wait
    // for each other at the rendezvous, in the aisles around it, and lock up (README
    // "Formations on the dispatch core"). A formation order whose first pick another one is
    // still heading for waits (accepted) until that one has started.
    std::set<PointId> heading;
    for (const auto& [id, o] : orders_) {
      if (o.order->formation && o.order->state == OrderState::kAssigned) heading.insert(o.order->picks.front());
    }
    std::vector<std::shared_ptr<const Order>> kept;
    for (auto& o : input.pending) {
      if (!o->formation || heading.insert(o->picks.front()).second) kept.push_back(std::move(o));
    }
    input.pending = std::move(kept);
    if (input.pending.empty()) return std::nullopt;
  }
  for (const auto& [id_of, robot] : bidders) {
    const std::string& id = *id_of;
    const BookRobot& r = *robot;
    RoundRobot rr;
    rr.id = id;
    rr.kind = r.robot.kind;
    rr.start = StartOf(r);
    if (r.has_assignment && !r.assignment.order_ids.empty()) {
      if (!r.round_copy) r.round_copy = std::make_shared<const Assignment>(r.assignment);
      rr.assignment = r.round_copy;
      for (const auto& order_id : r.assignment.order_ids) {
        const BookOrder* o = order(order_id);
        rr.queue.push_back(o ? o->order : nullptr);
      }
    }
    rr.last_reached = r.progress.last_reached;
    input.robots.push_back(std::move(rr));
    commit.keys[id] = KeyOf(r);
  }
  return input;
}

Change DispatchCore::PlanAwards(RoundCommit& commit, std::size_t max, double now) const {
  Change c;
  c.time = now;
  std::set<std::string> fresh;  // robots that had no orders: their plan is sent whole
  std::map<std::string, std::uint64_t> first_new;
  const std::size_t end = std::min(commit.awards.size(), commit.next + max);
  for (; commit.next < end; ++commit.next) {
    const RoundAward& a = commit.awards[commit.next];
    const BookOrder* o = order(a.order_id);
    if (!o || o->order->state != OrderState::kAccepted) continue;  // cancelled meanwhile
    const std::vector<std::string>& winners = a.award.winners;
    bool valid = true;
    for (const auto& w : winners) {
      if (commit.spoiled.count(w) != 0) valid = false;
      if (c.plans.count(w) != 0) continue;  // checked at its first award of this chunk
      const BookRobot* r = robot(w);
      auto key = commit.keys.find(w);
      if (!r || key == commit.keys.end() || !Eligible(*r) || !(KeyOf(*r) == key->second)) valid = false;
    }
    if (!valid) {
      // Computed on a robot that has moved on (or on an award before it that was dropped):
      // later awards of the round to these robots built on it too.
      commit.spoiled.insert(winners.begin(), winners.end());
      commit.again = true;
      continue;
    }
    for (std::size_t k = 0; k < winners.size(); ++k) {
      const std::string& w = winners[k];
      auto [it, first] = c.plans.try_emplace(w);
      Assignment& plan = it->second;
      if (first) {
        const BookRobot& r = robots_.at(w);
        if (r.has_assignment) plan = r.assignment;
        if (!r.has_assignment || r.assignment.order_ids.empty()) fresh.insert(w);
      }
      plan.robot_id = w;
      const std::uint64_t seq =
          AppendOrder(plan, a.order_id, a.segments[k], a.after_departure[k], first && fresh.count(w) != 0, now);
      if (first) first_new[w] = seq;
    }
    OrderChange line;
    line.order_id = a.order_id;
    line.to = OrderState::kAssigned;
    line.robots = winners;
    line.detail = a.award.reason;
    line.award = commit.next;
    c.orders.push_back(std::move(line));
  }
  for (const auto& [w, plan] : c.plans) {
    const bool whole = fresh.count(w) != 0;
    c.sends.push_back({w, whole ? PlanSend::Kind::kFull : PlanSend::Kind::kUpdate, whole ? 0 : first_new[w], {}, {}});
  }
  return c;
}

void DispatchCore::Committed(RoundCommit& commit, const Change& change) const {
  for (const auto& [id, plan] : change.plans) {
    if (const BookRobot* r = robot(id)) commit.keys[id] = KeyOf(*r);
  }
}

// --- Applying ------------------------------------------------------------------------------

void DispatchCore::ApplyOrder(const OrderChange& line) {
  auto it = orders_.find(line.order_id);
  if (it == orders_.end()) return;
  BookOrder& b = it->second;
  if (!line.to) return;
  if (IsTerminal(*line.to)) {
    orders_.erase(it);
    if (*line.to == OrderState::kCompleted) allocation_due_ = true;
    return;
  }
  auto copy = std::make_shared<Order>(*b.order);
  copy->state = *line.to;
  b.order = std::move(copy);
  if (line.robots) b.robots = *line.robots;
  if (*line.to == OrderState::kAccepted) {  // back for re-allocation
    if (!line.lost_at.empty()) {
      b.lost_there = b.lost_at == line.lost_at ? b.lost_there + 1 : 1;
      b.lost_at = line.lost_at;
    }
    allocation_due_ = true;
  }
  // A formation at its first pick: the next formation to that pick may be allocated (MakeRound).
  if (options_.one_formation_per_pick && *line.to == OrderState::kInProgress && b.order->formation) {
    allocation_due_ = true;
  }
}

std::vector<RobotCommand> DispatchCore::Apply(const Change& change) {
  for (const OrderChange& line : change.orders) ApplyOrder(line);
  for (const auto& [order_id, members] : change.dropped_by) {
    if (auto it = orders_.find(order_id); it != orders_.end()) it->second.dropped_by = members;
    allocation_due_ = true;  // a member's plan is shorter: it may bid again
  }
  for (const auto& [id, plan] : change.plans) {
    BookRobot* r = FindRobot(id);
    if (!r) continue;
    r->assignment = plan;
    r->round_copy.reset();
    r->has_assignment = true;
    r->robot.task_queue = plan.order_ids;
  }
  for (const auto& [id, marks] : change.marks) {
    BookRobot* r = FindRobot(id);
    if (!r) continue;
    const bool was_held = !r->marks.HeldFor().empty();
    r->marks = marks;
    if (gate_) {
      gate_->SetPaused(id, marks.HeldFor());
      if (marks.off_floor && !r->connected) gate_->Remove(id);
    }
    if (was_held && marks.HeldFor().empty()) allocation_due_ = true;  // it may bid again
  }
  // The gate learns every plan before any is sent (a formation needs all three members').
  for (const auto& [id, plan] : change.plans) {
    if (const BookRobot* r = robot(id)) SyncGate(*r);
  }
  std::vector<RobotCommand> out;
  for (const PlanSend& s : change.sends) {
    const BookRobot* r = robot(s.robot);
    if (!r) continue;
    if (s.kind == PlanSend::Kind::kCancel) {
      RobotMessage m;
      m.kind = RobotMessage::Kind::kCancel;
      m.order_ids = s.cancelled;
      m.reason = s.reason;
      out.push_back({s.robot, std::move(m)});
    } else {
      out.push_back({s.robot, PlanMessage(*r, s.kind == PlanSend::Kind::kFull, s.from_sequence)});
    }
  }
  return out;
}

GatePlan DispatchCore::GatePlanOf(const BookRobot& r) const {
  std::map<std::string, std::vector<std::string>> teams;
  double release = std::numeric_limits<double>::infinity();
  for (const auto& id : r.assignment.order_ids) {
    const BookOrder* o = order(id);
    if (!o) continue;
    if (o->order->formation) teams[id] = o->robots;
    release = std::min(release, o->order->created_time);
  }
  GatePlan plan = ToGatePlan(r.assignment, std::move(teams));
  plan.release = release;
  return plan;
}

void DispatchCore::SyncGate(const BookRobot& r) {
  if (!gate_) return;
  gate_->SetPlan(r.robot.id, r.has_assignment ? GatePlanOf(r) : GatePlan{});
}

RobotMessage DispatchCore::PlanMessage(const BookRobot& r, bool full, std::uint64_t from_sequence) const {
  RobotMessage m;
  m.kind = full ? RobotMessage::Kind::kAssignment : RobotMessage::Kind::kPlanUpdate;
  const Assignment& a = r.assignment;
  m.plan_id = a.plan_id;
  m.from_sequence = from_sequence;
  m.order_ids = a.order_ids;
  // Released: what the traffic gate has released so far (everything without traffic control).
  const std::uint64_t released = ReleasedUpTo(r.robot.id);
  const std::vector<std::string> order_of = OrdersOfWaypoints(a);
  for (std::size_t i = 0; i < a.plan.waypoints.size(); ++i) {
    const Waypoint& w = a.plan.waypoints[i];
    if (!full && static_cast<std::uint64_t>(w.seq) < from_sequence) continue;
    m.waypoints.push_back({w, order_of[i], static_cast<std::uint64_t>(w.seq) <= released});
  }
  m.released_up_to = released;
  for (const auto& id : a.order_ids) {
    const BookOrder* o = order(id);
    if (o && o->order->formation) {
      m.formation_members = o->robots;
      break;
    }
  }
  return m;
}

}  // namespace dispatch::engine
