// Dispatcher: allocation rounds (see dispatcher.h, "Allocation"). The loop copies a round's
// inputs (AllocatePending); the allocation worker builds the FleetState from them and runs the
// strategy (RunRound); the loop commits the awards that are still valid (CommitRound).
#include <spdlog/spdlog.h>

#include <algorithm>
#include <map>

#include "server/dispatcher.h"
#include "server/explanation.h"
#include "server/json_convert.h"

namespace dispatch::server {
namespace {

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
  auto input = std::make_shared<engine::RoundInput>();
  // The round reads the orders through their views (kept alive by the copy, never copied).
  auto order_of = [](const std::shared_ptr<const OrderView>& view) {
    return std::shared_ptr<const engine::Order>(view, &view->record.order);
  };
  for (const auto& view : orders_) {
    if (view->record.order.state == engine::OrderState::kAccepted) input->pending.push_back(order_of(view));
  }
  if (input->pending.empty()) return;
  std::vector<std::string> ids;
  for (const auto& [id, r] : robots_) {
    if (Eligible(r)) ids.push_back(id);
  }
  if (ids.empty()) return;
  std::sort(ids.begin(), ids.end(), engine::NaturalLess);
  std::sort(input->pending.begin(), input->pending.end(),
            [](const auto& a, const auto& b) { return engine::AllocationOrderLess(*a, *b); });
  input->now = Now();
  auto keys = std::make_shared<std::map<std::string, RoundKey>>();  // moved into the commit
  for (const auto& id : ids) {
    const RobotRuntime& r = robots_.at(id);
    engine::RoundRobot robot;
    robot.id = id;
    robot.start = StartOf(r);
    if (HasOrders(r.assignment, r.has_assignment)) {
      robot.assignment = r.assignment;
      for (const auto& order_id : r.assignment.order_ids) {
        auto view = Find(order_id);
        robot.queue.push_back(view ? order_of(view) : nullptr);
      }
    }
    robot.last_reached = r.progress.last_reached;
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

std::vector<Dispatcher::RoundAward> Dispatcher::RunRound(const engine::RoundInput& input) {
  engine::RoundResult round = rounds_->Run(input);
  for (const std::string& note : round.notes) spdlog::warn("{}", note);
  std::vector<RoundAward> out;
  for (engine::RoundAward& plan : round.awards) {
    RoundAward a;
    a.record = {std::move(plan.award), options_.allocation.alpha, options_.allocation.beta,
                options_.allocation.zeta, input.now};
    a.plan = std::move(plan);
    KeepBestBids(a.record);
    a.detail = AllocationDetail(a.record);
    out.push_back(std::move(a));
  }
  return out;
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
    auto view = Find(a.plan.order_id);
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
      plan.robot_id = w;
      const std::uint64_t first_new = engine::AppendOrder(plan, a.plan.order_id, a.plan.segments[k],
                                                          a.plan.after_departure[k], first && wk.fresh, now);
      if (first) wk.first_new = first_new;
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
      t.order_id = a.plan.order_id;
      t.to = engine::OrderState::kAssigned;
      t.time = now;
      t.robots = a.record.award.winners;
      t.detail = a.record.award.reason;
      auto e1 = s.TransitionOrder(t);
      if (!e1.ok()) return e1.error();
      events.push_back(*e1);
      auto e2 = s.AppendProgress(a.plan.order_id, now, a.detail);
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
    auto view = std::make_shared<OrderView>(*Find(a.plan.order_id));
    view->record.order.state = engine::OrderState::kAssigned;
    view->record.robots = a.record.award.winners;
    view->record.updated_time = now;
    view->explanation = a.record;
    Put(view);
    if (options_.metrics) options_.metrics->ObserveAllocation(a.plan.seconds);
    spdlog::info("order {} assigned: {}", a.plan.order_id, a.record.award.reason);
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
