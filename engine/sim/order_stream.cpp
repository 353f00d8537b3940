// Order-stream simulation: the loop, allocation rounds, single robots, the distance series.
// Formations are in order_stream_teams.cpp.
#include "engine/sim/order_stream.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <unordered_map>

#include "engine/allocation/allocator.h"
#include "engine/fleet/formation.h"
#include "engine/sim/order_stream_impl.h"

namespace dispatch::engine {
namespace stream_sim {
namespace {

double ReleaseOf(const Order& o) { return o.release_time.value_or(o.created_time); }

}  // namespace

StreamSim::StreamSim(std::shared_ptr<const WarehouseMap> map, std::shared_ptr<const RouteTable> routes,
                     const StreamConfig& config, TrafficController ctl)
    : map_(std::move(map)), routes_(std::move(routes)), config_(config), ctl_(std::move(ctl)),
      clearance_(config.traffic.point_clearance), radius_(FormationRadius()) {}

Status StreamSim::Init(const std::vector<FleetRobot>& robots, std::vector<Order> orders) {
  if (robots.empty()) return InvalidArgument("order stream: no robots");
  if (config_.strategy != AllocationStrategy::kPreassigned) {  // the service's registry
    auto made = MakeAllocator(AllocationStrategyName(config_.strategy));
    if (!made.ok()) return made.error();
    allocator_ = std::move(made).value();
  }
  // Formation agents are bots too (at most one per joined robot); references stay valid.
  bots_.reserve(2 * robots.size());
  for (const FleetRobot& fr : robots) {
    auto r = ctl_.AddRobot(fr.id, fr.start);
    if (!r.ok()) return r.error();
    Bot b;
    b.id = fr.id;
    b.home = fr.start;
    bots_.push_back(std::move(b));
  }
  for (const Order& o : orders) {
    if (o.formation && robots.size() < static_cast<std::size_t>(kFormationTeamSize)) {
      return InvalidArgument("order stream: formation order " + o.id + " needs " +
                             std::to_string(kFormationTeamSize) + " robots, the floor has " +
                             std::to_string(robots.size()));
    }
    StreamOrderOutcome oc;
    oc.order_id = o.id;
    oc.release_time = ReleaseOf(o);
    out_.orders.push_back(oc);
  }
  terminal_of_.assign(out_.orders.size(), false);
  std::vector<std::size_t> idx(orders.size());
  for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = i;
  std::stable_sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) {
    return ReleaseOf(orders[a]) < ReleaseOf(orders[b]);
  });
  for (std::size_t i : idx) {
    orders_.push_back(std::move(orders[i]));
    outcome_of_.push_back(i);
  }
  const WarehouseMap& m = *map_;
  const double cap = config_.distance_cap;
  cols_ = std::max(1, static_cast<int>(std::ceil((m.floor_max().x() - m.floor_min().x()) / cap)) + 1);
  rows_ = std::max(1, static_cast<int>(std::ceil((m.floor_max().y() - m.floor_min().y()) / cap)) + 1);
  head_.assign(static_cast<std::size_t>(cols_) * static_cast<std::size_t>(rows_), -1);
  head_stamp_.assign(head_.size(), 0);
  next_in_cell_.assign(bots_.capacity(), -1);
  return Ok{};
}

void StreamSim::Complete(std::size_t outcome, double t) {
  if (terminal_of_[outcome]) return;
  terminal_of_[outcome] = true;
  StreamOrderOutcome& oc = out_.orders[outcome];
  oc.completed = true;
  oc.completion_time = t;
  ++out_.completed;
  ++terminal_;
}

void StreamSim::Fail(std::size_t outcome, const std::string& why) {
  if (terminal_of_[outcome]) return;
  terminal_of_[outcome] = true;
  out_.orders[outcome].failure = why;
  ++terminal_;
}

bool StreamSim::Remaining(const Task& task, std::size_t first, PlanTask& pt) {
  if (first > task.picks.size()) return false;
  pt.picks.assign(task.picks.begin() + static_cast<std::ptrdiff_t>(std::min(first, task.picks.size())),
                  task.picks.end());
  pt.drop = task.drop;
  pt.work_time = task.work;
  if (pt.picks.empty()) {  // heading to the drop: one stop, its t_w split over n_c = 2
    pt.picks = {task.drop};
    pt.work_time = task.work / 2.0;
  }
  return true;
}

// Allocates every order released by t against the robots' current state.
void StreamSim::Release(double t) {
  if (config_.allocation_period > 0) {
    if (t + kTiny < next_allocation_) return;
    while (next_allocation_ <= t + kTiny) next_allocation_ += config_.allocation_period;
  }
  std::vector<Order> batch;
  while (next_release_ < orders_.size() && ReleaseOf(orders_[next_release_]) <= t + kTiny) {
    batch.push_back(orders_[next_release_]);
    ++next_release_;
  }
  if (batch.empty()) return;
  std::vector<FleetRobot> fleet;
  std::vector<std::size_t> bot_of;
  for (std::size_t r = 0; r < bots_.size(); ++r) {
    const Bot& b = bots_[r];
    if (b.removed || b.agent) continue;
    PointId start = kNoPoint;
    double ready = t;
    if (b.slot != Slot::kNone) {
      MemberStart(r, t, start, ready);
    } else {
      const bool moving = ctl_.Next(r) != kNoPoint;
      start = moving ? ctl_.Next(r) : ctl_.At(r);
      ready = t + (moving ? (b.len - b.s) / b.speed : 0.0) + b.dwell;
    }
    fleet.push_back({b.id, start, ready});
    bot_of.push_back(r);
  }
  std::unordered_map<std::string, std::size_t> by_id;
  for (std::size_t i = 0; i < bot_of.size(); ++i) by_id.emplace(fleet[i].id, bot_of[i]);
  const std::size_t first_k = next_release_ - batch.size();
  if (config_.strategy == AllocationStrategy::kPreassigned) {
    for (std::size_t k = first_k; k < next_release_; ++k) {
      const Order& o = orders_[k];
      if (!o.formation) {
        auto it = std::find_if(config_.preassigned.begin(), config_.preassigned.end(),
                               [&](const auto& p) { return p.first == o.id; });
        auto bot = it == config_.preassigned.end() ? by_id.end() : by_id.find(it->second);
        if (bot == by_id.end()) {
          Fail(outcome_of_[k], "allocation: order not preassigned to a robot on the floor");
          continue;
        }
        Enqueue(bot->second, k);
        continue;
      }
      // A formation order: every robot listed for it, leader first, three distinct ones.
      std::vector<std::size_t> members;
      for (const auto& [order, robot] : config_.preassigned) {
        auto bot = order == o.id ? by_id.find(robot) : by_id.end();
        if (bot != by_id.end() && std::find(members.begin(), members.end(), bot->second) == members.end()) {
          members.push_back(bot->second);
        }
      }
      if (members.size() != static_cast<std::size_t>(kFormationTeamSize)) {
        Fail(outcome_of_[k], "allocation: formation order not preassigned to 3 distinct robots on the floor");
        continue;
      }
      EnqueueTeam(members, k);
    }
    return;
  }
  auto created = FleetState::Create(map_, routes_, fleet, config_.allocation, zone_index_);
  if (!created.ok()) {
    for (std::size_t k = first_k; k < next_release_; ++k) {
      Fail(outcome_of_[k], "allocation: " + created.error().message);
    }
    return;
  }
  FleetState state = std::move(created).value();
  zone_index_ = state.zone_index();
  // Re-queue every robot's unfinished tasks (remaining picks + drop). A formation member's
  // part counts as its own task here: where and when its queue ends is what bids need.
  for (std::size_t i = 0; i < bot_of.size(); ++i) {
    const Bot& b = bots_[bot_of[i]];
    for (std::size_t k = 0; k < b.tasks.size(); ++k) {
      const Task& task = b.tasks[k];
      PlanTask pt;
      const bool left = k == 0 && task.team >= 0 && b.slot != Slot::kNone
                            ? MemberRemaining(task, pt)
                            : Remaining(task, task.next_stop + (k == 0 && b.dwell > 0 ? 1 : 0), pt);
      if (left) (void)state.AssignSingle(i, out_.orders[task.order].order_id, pt);
    }
  }
  Allocator& allocator = *allocator_;
  std::unordered_map<std::string, std::size_t> order_index;
  for (std::size_t k = first_k; k < next_release_; ++k) order_index.emplace(orders_[k].id, k);
  for (const OrderAllocation& a : AllocateAll(allocator, batch, state)) {
    const std::size_t k = order_index.at(a.order_id);
    const std::size_t need = static_cast<std::size_t>(orders_[k].team_size());
    if (!a.award.ok() || a.award->winners.size() != need) {
      Fail(outcome_of_[k], a.award.ok() ? "allocation: no winner" : "allocation: " + a.award.error().message);
      continue;
    }
    if (orders_[k].formation) {
      std::vector<std::size_t> members;
      for (const std::string& id : a.award->winners) members.push_back(by_id.at(id));
      EnqueueTeam(members, k);
    } else {
      Enqueue(by_id.at(a.award->winners.front()), k);
    }
  }
}

void StreamSim::Enqueue(std::size_t r, std::size_t k) {
  const Order& o = orders_[k];
  Task task;
  task.order = outcome_of_[k];
  task.picks = o.picks;
  task.drop = o.drop;
  task.work = config_.allocation.work_time_override.value_or(o.work_time);
  out_.orders[task.order].robot = bots_[r].id;
  bots_[r].parked_aside = false;
  bots_[r].tasks.push_back(std::move(task));
  ctl_.SetIdle(r, false);
}

void StreamSim::FailTasks(std::size_t r, const std::string& why) {
  for (const Task& task : bots_[r].tasks) Fail(task.order, why);
  bots_[r].tasks.clear();
  SyncGroup(r);
}

void StreamSim::FinishStop(std::size_t r, double t) {
  Bot& b = bots_[r];
  ctl_.SetWorking(r, false);
  Task& task = b.tasks.front();
  if (task.next_stop < task.picks.size()) {
    ++task.next_stop;
    ctl_.SetLoaded(r, true);
    return;
  }
  if (b.agent) {  // a formation's drop
    TeamDropDone(r, t);
    return;
  }
  Complete(task.order, t);
  b.tasks.pop_front();
  ctl_.SetLoaded(r, false);
  ctl_.SetIdle(r, b.tasks.empty());
  SyncGroup(r);
}

void StreamSim::Move(std::size_t r, double t0) {
  Bot& b = bots_[r];
  if (b.removed) return;
  if (b.slot != Slot::kNone) {  // a formation member: the team moves it
    MoveMember(r);
    return;
  }
  if (b.agent && teams_[static_cast<std::size_t>(b.team)].phase != Team::Phase::kMoving) return;
  const double weight = b.agent ? static_cast<double>(kFormationTeamSize) : 1.0;  // robots it moves
  // An agent keeps its point until every member is clear of it (Chu2024 eq. (11)).
  const double leave_after = b.agent ? clearance_ + 2.0 * radius_ : clearance_;
  const double dt = config_.time_step;
  double budget = dt;
  for (int iter = 0; iter < 16 && budget > kTiny && !b.removed; ++iter) {
    const double now = t0 + (dt - budget);
    if (b.dwell > 0) {
      const double d = std::min(b.dwell, budget);
      b.dwell -= d;
      budget -= d;
      if (b.dwell > kTiny) break;
      b.dwell = 0;
      FinishStop(r, t0 + (dt - budget));
      if (b.agent && teams_[static_cast<std::size_t>(b.team)].phase != Team::Phase::kMoving) break;
      continue;
    }
    if (b.moving) {
      if (b.turn_s < b.turn_len) {  // a formation turns in place first (members on a circle)
        const double d = std::min(b.turn_len - b.turn_s, budget);
        b.turn_s += d;
        budget -= d;
        out_.total_distance += weight * d * b.speed;
        if (b.turn_s < b.turn_len - kTiny) break;
        b.turn_s = b.turn_len;
        continue;
      }
      const double rem = (b.len - b.s) / b.speed;
      if (rem <= budget + kTiny) {
        const double d = std::min(rem, budget);
        budget -= d;
        out_.total_distance += weight * (b.len - b.s);
        b.s = b.len;
        b.moving = false;
        ctl_.Arrived(r, t0 + (dt - budget));
        continue;
      }
      b.s += budget * b.speed;
      out_.total_distance += weight * budget * b.speed;
      budget = 0;
      if (!b.left_start && b.s >= leave_after) {
        ctl_.LeftPoint(r);
        b.left_start = true;
      }
      break;
    }
    if (!ctl_.HasRoute(r)) {
      const PointId at = ctl_.At(r);
      PointId target = kNoPoint;
      if (!b.tasks.empty()) {
        target = b.tasks.front().Stop();
      } else if (config_.return_home && !b.agent && IsServicePoint(map_->point(b.home).kind)) {
        target = b.home;
      }
      const bool member = !b.agent && !b.tasks.empty() && b.tasks.front().team >= 0;
      const bool holds = member && HoldsForRendezvous(b, now);
      if (member) ctl_.SetIdle(r, holds);  // waiting for the rendezvous call: may be nudged
      if (target == kNoPoint || (b.tasks.empty() && at == target) || holds) {
        // Idle away from a station: leave service points and corridors to the others.
        if ((b.tasks.empty() || holds) && config_.idle_step_aside && !b.parked_aside && ctl_.StepAside(r)) {
          b.parked_aside = true;
          continue;
        }
        break;
      }
      if (at == target) {
        if (!b.agent && b.tasks.front().team >= 0) {  // a member at the rendezvous point
          if (!Join(r, now)) WaitToJoin(r, budget);
          break;
        }
        b.dwell = b.tasks.front().work;
        ctl_.SetWorking(r, true, now + b.dwell);
        if (b.dwell <= 0) FinishStop(r, now);
        continue;
      }
      auto path = routes_->Path(at, target);
      if (!path.ok()) {
        if (b.tasks.empty()) break;  // cannot get home: stay
        Fail(b.tasks.front().order, "unreachable: " + path.error().message);
        if (b.agent) {  // the formation cannot go on: its members leave it here
          DissolveBlocked(r);
          break;
        }
        b.tasks.pop_front();
        SyncGroup(r);
        continue;
      }
      (void)ctl_.SetRoute(r, std::move(path->points));
      continue;
    }
    // A member one point before the rendezvous point its team's agent holds: into its slot.
    if (!b.agent && !b.tasks.empty() && b.tasks.front().team >= 0 && Join(r, now)) break;
    const TrafficDecision d = ctl_.Request(r, now);
    if (d == TrafficDecision::kGo) {
      const PointId from = ctl_.At(r), to = ctl_.Next(r);
      b.from = map_->point(from).position;
      b.to = map_->point(to).position;
      const Arc& arc = map_->arc(*map_->FindArc(from, to));
      b.len = arc.length;
      b.speed = arc.max_speed > 0 ? std::min(config_.allocation.speed, arc.max_speed)
                                  : config_.allocation.speed;
      b.s = 0;
      b.left_start = false;
      b.moving = true;
      b.waiting = false;
      b.turn_s = b.turn_len = 0;
      if (b.agent) {  // Chu2024 §3.2: the structure rotates about its centre to the new heading
        const Eigen::Vector2d dir = b.to - b.from;
        const double heading = std::atan2(dir.y(), dir.x());
        const double turn = std::remainder(heading - b.heading, 2.0 * std::numbers::pi);
        b.turn_from = b.heading;
        b.heading = heading;
        b.turn_len = radius_ * std::abs(turn) / b.speed;
        if (b.turn_len < kTiny) b.turn_len = 0;
      }
      continue;
    }
    if (d == TrafficDecision::kReplanned) continue;
    if (d == TrafficDecision::kWait) {
      out_.total_waiting_time += weight * budget;
      if (!b.waiting) ++out_.stops;
      b.waiting = true;
      break;
    }
    // kBlocked: the robot is taken off the floor as faulted (Wang2019: "故障状态"). A
    // blocked formation's order fails and its members leave it where it stands.
    const std::string why = b.id + ": " + ctl_.why(r);
    out_.blocked.push_back(why);
    FailTasks(r, "blocked: " + why);
    if (b.agent) {
      DissolveBlocked(r);
      break;
    }
    ctl_.Remove(r);
    b.removed = true;
    b.moving = false;
  }
}

Eigen::Vector2d StreamSim::Position(std::size_t r) const {
  const Bot& b = bots_[r];
  switch (b.slot) {
    case Slot::kToSlot:
    case Slot::kOut:
      if (b.s < b.via_s) return b.from + (b.s / b.via_s) * (b.via - b.from);
      if (b.len - b.via_s <= kTiny) return b.to;
      return (b.via_s > 0 ? b.via : b.from) + ((b.s - b.via_s) / (b.len - b.via_s)) * (b.to - (b.via_s > 0 ? b.via : b.from));
    case Slot::kInSlot:
      return SlotPosition(teams_[static_cast<std::size_t>(b.team)], b.member);
    case Slot::kNone:
      break;
  }
  if (b.moving && b.len > 0) return b.from + (b.s / b.len) * (b.to - b.from);
  return map_->point(ctl_.At(r)).position;
}

// Members of one formation are one agent from their approach until they have left its drop
// (as in TrafficGate and CheckSafety's groups).
bool StreamSim::SameAgent(const Bot& a, const Bot& b) const {
  return (a.team >= 0 && (a.team == b.team || a.team == b.former)) ||
         (a.former >= 0 && (a.former == b.team || a.former == b.former));
}

void StreamSim::Sample(double t) {
  const double cap = config_.distance_cap;
  const Eigen::Vector2d origin = map_->floor_min();
  if (++stamp_ == 0) {
    std::fill(head_stamp_.begin(), head_stamp_.end(), 0);
    stamp_ = 1;
  }
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t r = 0; r < bots_.size(); ++r) {
    const Bot& b = bots_[r];
    if (b.removed || b.agent) continue;
    const Eigen::Vector2d p = Position(r);
    const int cx = std::clamp(static_cast<int>((p.x() - origin.x()) / cap), 0, cols_ - 1);
    const int cy = std::clamp(static_cast<int>((p.y() - origin.y()) / cap), 0, rows_ - 1);
    const bool teamed = b.team >= 0 || b.former >= 0;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int x = cx + dx, y = cy + dy;
        if (x < 0 || y < 0 || x >= cols_ || y >= rows_) continue;
        const auto cell = static_cast<std::size_t>(y) * static_cast<std::size_t>(cols_) +
                          static_cast<std::size_t>(x);
        if (head_stamp_[cell] != stamp_) continue;
        for (int o = head_[cell]; o >= 0; o = next_in_cell_[static_cast<std::size_t>(o)]) {
          const auto other = static_cast<std::size_t>(o);
          if (teamed && SameAgent(b, bots_[other])) continue;
          best = std::min(best, (Position(other) - p).norm());
        }
      }
    }
    const auto cell = static_cast<std::size_t>(cy) * static_cast<std::size_t>(cols_) +
                      static_cast<std::size_t>(cx);
    if (head_stamp_[cell] != stamp_) {
      head_stamp_[cell] = stamp_;
      head_[cell] = -1;
    }
    next_in_cell_[r] = head_[cell];
    head_[cell] = static_cast<int>(r);
  }
  if (best > cap) best = std::numeric_limits<double>::infinity();
  out_.overall_min_distance = std::min(out_.overall_min_distance, best);
  if (config_.check_safety || config_.record_frames) Record(t);
  if (config_.record_series) {
    out_.times.push_back(t);
    out_.min_distance.push_back(best);
  }
}

void StreamSim::Record(double t) {
  SafetyFrame& frame = frames_.emplace_back();
  frame.t = t;
  for (std::size_t r = 0; r < bots_.size(); ++r) {
    const Bot& b = bots_[r];
    if (b.removed || b.agent) continue;
    if (b.team < 0 && b.former < 0) {
      frame.robots.push_back({b.id, b.id, b.id, false, Position(r)});
      continue;
    }
    const auto team_name = [&](int team) {
      return team < 0 ? std::string() : "team " + out_.orders[teams_[static_cast<std::size_t>(team)].order].order_id;
    };
    const bool in_slot = b.slot == Slot::kInSlot;
    const std::string group = team_name(b.team >= 0 ? b.team : b.former);
    frame.robots.push_back({b.id, in_slot ? "formation " + group.substr(5) : b.id, group, in_slot, Position(r),
                            b.team >= 0 ? team_name(b.former) : std::string()});
  }
}

StreamResult StreamSim::Run() {
  const double dt = config_.time_step;
  std::size_t step = 0;
  double t = 0;
  Sample(0.0);
  while (terminal_ < out_.orders.size() && t < config_.max_time) {
    Release(t);
    StepTeams(t);
    for (std::size_t r = 0; r < bots_.size(); ++r) Move(r, t);
    ctl_.ResolveDeadlocks(t);
    ++step;
    t = static_cast<double>(step) * dt;
    Sample(t);
  }
  out_.steps = step;
  out_.end_time = t;
  double sum = 0;
  for (StreamOrderOutcome& o : out_.orders) {
    if (o.completed) {
      out_.makespan = std::max(out_.makespan, o.completion_time);
      sum += o.completion_time - o.release_time;
    } else if (o.failure.empty()) {
      o.failure = "simulation time limit reached";
      o.open_at_limit = true;
    }
  }
  if (out_.completed > 0) {
    out_.mean_completion = sum / static_cast<double>(out_.completed);
    if (out_.makespan > 0) {
      out_.throughput_per_hour = static_cast<double>(out_.completed) / out_.makespan * 3600.0;
    }
  }
  out_.traffic = ctl_.stats();
  if (config_.check_safety) {
    TrafficConfig rules;
    rules.formation_radius = radius_;
    rules.epsilon_single_single = clearance_;
    rules.epsilon_single_formation = clearance_ + radius_;
    rules.epsilon_formation_formation = clearance_ + 2.0 * radius_;
    // The controller grants per movement and may re-plan a robot inside I_w (a detour, a
    // back-off): one that entered behind another may leave by another point.
    SafetyCheckOptions options;
    options.followers_may_diverge = true;
    out_.safety = CheckSafety(frames_, *map_, rules, options);
  }
  if (config_.record_frames) out_.frames = std::move(frames_);
  return std::move(out_);
}

}  // namespace stream_sim

const char* AllocationStrategyName(AllocationStrategy strategy) {
  switch (strategy) {
    case AllocationStrategy::kAuction: return "auction";
    case AllocationStrategy::kGreedy: return "greedy";
    case AllocationStrategy::kPreassigned: return "preassigned";
  }
  return "?";
}

Result<StreamResult> SimulateOrderStream(std::shared_ptr<const WarehouseMap> map,
                                         std::shared_ptr<const RouteTable> routes,
                                         const std::vector<FleetRobot>& robots,
                                         std::vector<Order> orders, const StreamConfig& config) {
  if (!map || !routes) return InvalidArgument("order stream: no map or route table");
  if (!(config.time_step > 0) || !std::isfinite(config.time_step) || !(config.max_time > 0) ||
      !(config.distance_cap > 0) || !(config.allocation_period >= 0)) {
    return InvalidArgument("order stream: time_step, max_time and distance_cap must be > 0");
  }
  Status valid = ValidateAllocationConfig(config.allocation);
  if (!valid.ok()) return valid.error();
  TrafficControllerConfig tc = config.traffic;
  tc.speed = config.allocation.speed;
  if (std::any_of(orders.begin(), orders.end(), [](const Order& o) { return o.formation; })) {
    tc.max_envelope = std::max(tc.max_envelope, FormationRadius());  // a formation's D_f
  }
  auto ctl = TrafficController::Create(map, tc);
  if (!ctl.ok()) return ctl.error();
  stream_sim::StreamSim sim(map, routes, config, std::move(ctl).value());
  Status init = sim.Init(robots, std::move(orders));
  if (!init.ok()) return init.error();
  return sim.Run();
}

}  // namespace dispatch::engine
