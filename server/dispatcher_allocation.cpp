// Dispatcher: allocation rounds (see dispatcher.h, "Allocation"). The loop copies a round's
// inputs (AllocatePending); the allocation worker builds the FleetState from them and runs the
// strategy (RunRound); the loop commits the awards that are still valid (CommitRound).
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <map>

#include "server/dispatcher.h"
#include "server/explanation.h"
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

// Awards stored per loop turn: a large round (a hundred orders, each explanation with the bids
// of every robot) would otherwise hold the loop for a quarter second.
constexpr std::size_t kCommitChunk = 4;

}  // namespace

bool Dispatcher::Eligible(const RobotRuntime& r) const {
  return r.link && r.record.robot.current_point != engine::kNoPoint &&
         r.record.robot.state != engine::RobotState::kFault && (!gate_ || gate_->Available(r.record.robot.id));
}

engine::PointId Dispatcher::StartOf(const RobotRuntime& r) const {
  // A new plan starts where the traffic controller has the robot (standing or arriving).
  const engine::PointId p = gate_ ? gate_->StartPoint(r.record.robot.id) : engine::kNoPoint;
  return p != engine::kNoPoint ? p : r.record.robot.current_point;
}

Dispatcher::RoundKey Dispatcher::KeyOf(const RobotRuntime& r) const {
  RoundKey key;
  key.plan_id = r.has_assignment ? r.assignment.plan_id : 0;
  if (HasOrders(r.assignment, r.has_assignment)) {
    key.last_order = r.assignment.order_ids.back();  // new work starts at its queue's end
  } else {
    key.start = StartOf(r);
  }
  return key;
}

void Dispatcher::AllocatePending() {
  allocation_due_ = false;
  if (round_running_) {
    round_again_ = true;  // after the running round is committed
    return;
  }
  retry_allocation_ = false;
  auto input = std::make_shared<RoundInput>();
  for (const auto& view : orders_) {
    if (view->record.order.state == engine::OrderState::kAccepted) input->pending.push_back(view);
  }
  if (input->pending.empty()) return;
  std::vector<std::string> ids;
  for (const auto& [id, r] : robots_) {
    if (Eligible(r)) ids.push_back(id);
  }
  if (ids.empty()) return;
  std::sort(ids.begin(), ids.end(), NaturalLess);
  std::sort(input->pending.begin(), input->pending.end(), [](const auto& a, const auto& b) {
    const auto& x = a->record.order;
    const auto& y = b->record.order;
    if (x.priority != y.priority) return x.priority > y.priority;
    if (x.created_time != y.created_time) return x.created_time < y.created_time;
    return a->position < b->position;
  });
  input->now = Now();
  auto keys = std::make_shared<std::map<std::string, RoundKey>>();  // moved into the commit
  for (const auto& id : ids) {
    const RobotRuntime& r = robots_.at(id);
    RoundRobot robot;
    robot.id = id;
    robot.start = StartOf(r);
    if (HasOrders(r.assignment, r.has_assignment)) {
      robot.assignment = r.assignment;
      for (const auto& order_id : r.assignment.order_ids) robot.queue.push_back(Find(order_id));
    }
    robot.last_reached = r.last_reached;
    input->robots.push_back(std::move(robot));
    (*keys)[id] = KeyOf(r);
  }
  round_running_ = true;
  allocation_worker_->Run([this, input, keys](bool cancelled) {
    auto commit = std::make_shared<RoundCommit>();
    commit->keys = std::move(*keys);
    if (!cancelled) commit->awards = RunRound(*input);
    Post([this, commit] { CommitNext(commit); });
  });
}

void Dispatcher::CommitNext(std::shared_ptr<RoundCommit> commit) {
  if (!CommitRound(*commit)) {
    retry_allocation_ = true;  // the store failed: the rest stays accepted, tried on the next tick
  } else if (commit->next < commit->awards.size()) {
    Post([this, commit] { CommitNext(commit); });
    return;
  }
  round_running_ = false;
  if (round_again_) {
    round_again_ = false;
    allocation_due_ = true;
  }
}

std::vector<Dispatcher::RoundAward> Dispatcher::RunRound(const RoundInput& input) {
  std::vector<RoundAward> out;
  std::vector<engine::FleetRobot> fleet_robots;
  for (const RoundRobot& r : input.robots) {
    engine::FleetRobot f;
    f.id = r.id;
    f.start = r.start;
    f.ready_time = input.now;
    fleet_robots.push_back(f);
  }
  auto fleet = engine::FleetState::Create(map_, routes_, fleet_robots, options_.allocation, zone_index_);
  if (!fleet.ok()) {
    spdlog::error("allocation: {}", fleet.error().message);
    return out;
  }
  engine::FleetState state = std::move(fleet).value();
  zone_index_ = state.zone_index();  // one floor, one index: the next round skips the grid
  for (std::size_t i = 0; i < input.robots.size(); ++i) ReplayQueue(state, i, input.robots[i]);
  std::vector<bool> queued(input.robots.size());  // has orders (before or from this round)
  for (std::size_t i = 0; i < input.robots.size(); ++i) queued[i] = !input.robots[i].assignment.order_ids.empty();
  for (const auto& view : input.pending) {
    const engine::Order& order = view->record.order;
    if (static_cast<std::size_t>(order.team_size()) > input.robots.size()) continue;
    std::vector<std::size_t> old_sizes;
    for (std::size_t i = 0; i < state.robot_count(); ++i) old_sizes.push_back(state.plan(i).waypoints.size());
    const auto start = Clock::now();
    auto award = allocator_->Allocate(order, state);
    const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
    if (!award.ok()) {
      spdlog::warn("order {} not allocated (stays accepted): {}", order.id, award.error().message);
      continue;
    }
    RoundAward a;
    a.order_id = order.id;
    a.seconds = seconds;
    for (const auto& w : award->winners) {
      const std::size_t i = *state.FindRobot(w);
      const auto& fp = state.plan(i).waypoints;
      // A robot without a queue gets the whole plan (its start waypoint included).
      const std::size_t from = queued[i] ? old_sizes[i] : 0;
      queued[i] = true;
      a.segments.emplace_back(fp.begin() + static_cast<std::ptrdiff_t>(std::min(from, fp.size())), fp.end());
      a.after_departure.push_back(from > 0 && from <= fp.size() ? fp[from - 1].departure() : 0.0);
    }
    a.record = {std::move(award).value(), options_.allocation.alpha, options_.allocation.beta,
                options_.allocation.zeta, input.now};
    KeepBestBids(a.record);
    a.detail = AllocationDetail(a.record);
    out.push_back(std::move(a));
  }
  return out;
}

void Dispatcher::ReplayQueue(engine::FleetState& fleet, std::size_t index, const RoundRobot& r) const {
  const auto& plan = r.assignment;
  for (std::size_t k = 0; k < plan.order_ids.size(); ++k) {
    const auto& view = r.queue[k];
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
      spdlog::warn("allocation: queue of {} replayed up to {} only: {}", r.id, order.id,
                   assigned.error().message);
      return;
    }
  }
}

bool Dispatcher::CommitRound(RoundCommit& commit) {
  const double now = Now();
  auto& keys = commit.keys;
  auto& spoiled = commit.spoiled;
  // Each robot's plan after this round's awards (built on a copy, applied once stored).
  struct Work {
    RobotRuntime* robot = nullptr;
    storage::AssignmentRecord assignment;
    storage::RobotRecord record;
    bool fresh = false;           // it had no orders: the plan is sent whole
    std::uint64_t first_new = 0;  // its first new waypoint sequence
  };
  std::map<std::string, Work> work;
  std::vector<const RoundAward*> accepted;
  const std::size_t end = std::min(commit.awards.size(), commit.next + kCommitChunk);
  for (; commit.next < end; ++commit.next) {
    const RoundAward& a = commit.awards[commit.next];
    auto view = Find(a.order_id);
    if (!view || view->record.order.state != engine::OrderState::kAccepted) continue;  // cancelled meanwhile
    bool valid = true;
    for (const auto& w : a.record.award.winners) {
      if (spoiled.count(w) != 0) valid = false;
      if (work.count(w) != 0) continue;  // checked at its first award of the round
      const RobotRuntime* r = RobotOf(w);
      auto key = keys.find(w);
      if (!r || key == keys.end() || !Eligible(*r) || !(KeyOf(*r) == key->second)) valid = false;
    }
    if (!valid) {
      // Computed on a robot that has moved on (or on an award before it that was dropped):
      // later awards of the round to these robots built on it too.
      spoiled.insert(a.record.award.winners.begin(), a.record.award.winners.end());
      round_again_ = true;
      continue;
    }
    for (std::size_t k = 0; k < a.record.award.winners.size(); ++k) {
      const std::string& w = a.record.award.winners[k];
      auto [it, first] = work.try_emplace(w);
      Work& wk = it->second;
      if (first) {
        wk.robot = RobotOf(w);
        wk.assignment = wk.robot->assignment;
        wk.record = wk.robot->record;
        wk.fresh = !HasOrders(wk.robot->assignment, wk.robot->has_assignment);
        wk.record.next_sequence += 1;  // the one Assignment / PlanUpdate it gets
      }
      auto& plan = wk.assignment;
      std::int64_t next_seq = plan.released_up_to + 1;
      if (!plan.plan.waypoints.empty()) next_seq = std::max<std::int64_t>(next_seq, plan.plan.waypoints.back().seq + 1);
      const bool empty = plan.order_ids.empty() || (first && wk.fresh);
      if (empty) {
        plan.robot_id = w;
        plan.plan_id += 1;
        plan.plan.robot_id = w;
        plan.plan.waypoints.clear();
        plan.order_ids.clear();
      }
      if (first) wk.first_new = static_cast<std::uint64_t>(next_seq);
      // The replayed queue (see ReplayQueue) re-timed the robot's remaining work from the
      // round's start; the new segment never starts before the robot's actual plan ends.
      const auto& segment = a.segments[k];
      const double shift = empty || segment.empty() ? 0.0 : std::max(0.0, plan.plan.end_time() - a.after_departure[k]);
      for (engine::Waypoint wp : segment) {
        wp.seq = static_cast<int>(next_seq++);
        wp.eta += shift;
        plan.plan.waypoints.push_back(wp);
      }
      plan.order_ids.push_back(a.order_id);
      plan.released_up_to = next_seq - 1;
      plan.updated_time = now;
      wk.record.robot.task_queue = plan.order_ids;
    }
    accepted.push_back(&a);
  }
  if (accepted.empty()) return true;
  std::vector<storage::OrderEvent> events;
  auto committed = store_.RunInTransaction([&](storage::Store& s) -> engine::Status {
    events.clear();
    for (std::size_t i = 0; i < accepted.size(); ++i) {
      const RoundAward& a = *accepted[i];
      storage::OrderTransition t;
      t.order_id = a.order_id;
      t.to = engine::OrderState::kAssigned;
      t.time = now;
      t.robots = a.record.award.winners;
      t.detail = a.record.award.reason;
      auto e1 = s.TransitionOrder(t);
      if (!e1.ok()) return e1.error();
      events.push_back(*e1);
      auto e2 = s.AppendProgress(a.order_id, now, a.detail);
      if (!e2.ok()) return e2.error();
      events.push_back(*e2);
    }
    for (const auto& [id, wk] : work) {
      if (auto saved = s.SaveAssignment(wk.assignment); !saved.ok()) return saved.error();
      if (auto saved = s.UpsertRobot(wk.record); !saved.ok()) return saved.error();
    }
    return engine::Ok{};
  });
  if (!committed.ok()) {
    spdlog::error("awards of {} orders not stored (they stay accepted): {}", accepted.size(),
                  committed.error().message);
    return false;
  }
  for (std::size_t i = 0; i < accepted.size(); ++i) {
    const RoundAward& a = *accepted[i];
    auto view = std::make_shared<OrderView>(*Find(a.order_id));
    view->record.order.state = engine::OrderState::kAssigned;
    view->record.robots = a.record.award.winners;
    view->record.updated_time = now;
    view->explanation = a.record;
    Put(view);
    if (options_.metrics) options_.metrics->ObserveAllocation(a.seconds);
    spdlog::info("order {} assigned: {}", a.order_id, a.record.award.reason);
  }
  for (const auto& e : events) Journal(e);
  for (auto& [id, wk] : work) {
    RobotRuntime& r = *wk.robot;
    r.assignment = std::move(wk.assignment);
    r.has_assignment = true;
    r.record.robot.task_queue = r.assignment.order_ids;
  }
  // The gate learns every plan before any is sent (a formation needs all three members').
  for (auto& [id, wk] : work) SyncGate(*wk.robot);
  for (auto& [id, wk] : work) SendTo(*wk.robot, PlanMessage(*wk.robot, wk.fresh, wk.first_new));
  for (auto& [id, wk] : work) keys[id] = KeyOf(*wk.robot);  // the round's later awards build on these
  dirty_ = true;
  return true;
}

}  // namespace dispatch::server
