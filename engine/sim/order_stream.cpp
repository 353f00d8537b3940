#include "engine/sim/order_stream.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <unordered_map>

#include "engine/allocation/allocator.h"
#include "engine/allocation/auction_allocator.h"
#include "engine/allocation/greedy_allocator.h"

namespace dispatch::engine {
namespace {

constexpr double kTiny = 1e-9;

struct Task {
  std::size_t order = 0;  // index into the outcomes
  std::vector<PointId> picks;
  PointId drop = kNoPoint;
  double work = 0.0;
  std::size_t next_stop = 0;  // 0..picks.size(); picks.size() = the drop
  PointId Stop() const { return next_stop < picks.size() ? picks[next_stop] : drop; }
};

struct Bot {
  std::string id;
  PointId home = kNoPoint;
  std::deque<Task> tasks;
  double dwell = 0.0;  // work left at the current stop
  bool moving = false;
  Eigen::Vector2d from = Eigen::Vector2d::Zero(), to = Eigen::Vector2d::Zero();
  double s = 0.0, len = 0.0, speed = 1.0;
  bool waiting = false;
  bool removed = false;
  bool parked_aside = false;  // idle and already sent to a siding once
  bool left_start = false;    // past point_clearance on the current arc
};

class StreamSim {
 public:
  StreamSim(std::shared_ptr<const WarehouseMap> map, std::shared_ptr<const RouteTable> routes,
            const StreamConfig& config, TrafficController ctl)
      : map_(std::move(map)), routes_(std::move(routes)), config_(config), ctl_(std::move(ctl)),
        clearance_(config.traffic.point_clearance) {}

  Status Init(const std::vector<FleetRobot>& robots, std::vector<Order> orders);
  StreamResult Run();

 private:
  void Release(double t);
  void Enqueue(std::size_t r, std::size_t k);  // orders_[k] to robot r's queue
  void Move(std::size_t r, double t);
  void FinishStop(std::size_t r, double t);
  void FailTasks(std::size_t r, const std::string& why);
  Eigen::Vector2d Position(std::size_t r) const;
  void Sample(double t);

  std::shared_ptr<const WarehouseMap> map_;
  std::shared_ptr<const RouteTable> routes_;
  std::shared_ptr<const ZoneIndex> zone_index_;  // kept between allocation rounds
  const StreamConfig& config_;
  TrafficController ctl_;
  std::vector<Bot> bots_;
  std::vector<Order> orders_;           // by release time
  std::vector<std::size_t> outcome_of_;  // orders_[k] -> out_.orders index
  std::size_t next_release_ = 0;
  double next_allocation_ = 0.0;
  std::size_t terminal_ = 0;
  AuctionAllocator auction_;
  GreedyAllocator greedy_;
  StreamResult out_;
  double clearance_ = 0.6;  // TrafficControllerConfig::point_clearance
  // Spatial hash for the distance series.
  std::vector<int> head_;
  std::vector<std::uint32_t> head_stamp_;
  std::vector<int> next_in_cell_;
  std::uint32_t stamp_ = 0;
  int cols_ = 1, rows_ = 1;
  std::vector<SafetyFrame> frames_;  // check_safety
};

double ReleaseOf(const Order& o) { return o.release_time.value_or(o.created_time); }

Status StreamSim::Init(const std::vector<FleetRobot>& robots, std::vector<Order> orders) {
  if (robots.empty()) return InvalidArgument("order stream: no robots");
  for (const FleetRobot& fr : robots) {
    auto r = ctl_.AddRobot(fr.id, fr.start);
    if (!r.ok()) return r.error();
    Bot b;
    b.id = fr.id;
    b.home = fr.start;
    bots_.push_back(std::move(b));
  }
  for (const Order& o : orders) {
    if (o.formation) {
      return InvalidArgument("order stream: formation order " + o.id +
                             " (formations run in the plan simulator)");
    }
    StreamOrderOutcome oc;
    oc.order_id = o.id;
    oc.release_time = ReleaseOf(o);
    out_.orders.push_back(oc);
  }
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
  next_in_cell_.assign(bots_.size(), -1);
  return Ok{};
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
    if (b.removed) continue;
    const bool moving = ctl_.Next(r) != kNoPoint;
    const PointId start = moving ? ctl_.Next(r) : ctl_.At(r);
    const double ready = t + (moving ? (b.len - b.s) / b.speed : 0.0) + b.dwell;
    fleet.push_back({b.id, start, ready});
    bot_of.push_back(r);
  }
  std::unordered_map<std::string, std::size_t> by_id;
  for (std::size_t i = 0; i < bot_of.size(); ++i) by_id.emplace(fleet[i].id, bot_of[i]);
  auto fail = [&](const Order& o, const std::string& why) {
    StreamOrderOutcome& oc = out_.orders[outcome_of_[static_cast<std::size_t>(&o - orders_.data())]];
    oc.failure = why;
    ++terminal_;
  };
  if (config_.strategy == AllocationStrategy::kPreassigned) {
    for (std::size_t k = next_release_ - batch.size(); k < next_release_; ++k) {
      const Order& o = orders_[k];
      auto it = std::find_if(config_.preassigned.begin(), config_.preassigned.end(),
                             [&](const auto& p) { return p.first == o.id; });
      auto bot = it == config_.preassigned.end() ? by_id.end() : by_id.find(it->second);
      if (bot == by_id.end()) {
        fail(o, "allocation: order not preassigned to a robot on the floor");
        continue;
      }
      Enqueue(bot->second, k);
    }
    return;
  }
  auto created = FleetState::Create(map_, routes_, fleet, config_.allocation, zone_index_);
  if (!created.ok()) {
    for (std::size_t k = next_release_ - batch.size(); k < next_release_; ++k) {
      fail(orders_[k], "allocation: " + created.error().message);
    }
    return;
  }
  FleetState state = std::move(created).value();
  zone_index_ = state.zone_index();
  // Re-queue every robot's unfinished tasks (remaining picks + drop).
  for (std::size_t i = 0; i < bot_of.size(); ++i) {
    const Bot& b = bots_[bot_of[i]];
    for (std::size_t k = 0; k < b.tasks.size(); ++k) {
      const Task& task = b.tasks[k];
      std::size_t first = task.next_stop + (k == 0 && b.dwell > 0 ? 1 : 0);
      if (first > task.picks.size()) continue;  // working at the drop: in the ready time
      PlanTask pt;
      pt.picks.assign(task.picks.begin() + static_cast<std::ptrdiff_t>(std::min(first, task.picks.size())),
                      task.picks.end());
      pt.drop = task.drop;
      pt.work_time = task.work;
      if (pt.picks.empty()) {  // heading to the drop: one stop, its t_w split over n_c = 2
        pt.picks = {task.drop};
        pt.work_time = task.work / 2.0;
      }
      (void)state.AssignSingle(i, out_.orders[task.order].order_id, pt);
    }
  }
  Allocator& allocator = config_.strategy == AllocationStrategy::kAuction
                             ? static_cast<Allocator&>(auction_)
                             : static_cast<Allocator&>(greedy_);
  std::unordered_map<std::string, std::size_t> order_index;
  for (std::size_t k = next_release_ - batch.size(); k < next_release_; ++k) {
    order_index.emplace(orders_[k].id, k);
  }
  for (const OrderAllocation& a : AllocateAll(allocator, batch, state)) {
    const std::size_t k = order_index.at(a.order_id);
    if (!a.award.ok() || a.award->winners.empty()) {
      fail(orders_[k], a.award.ok() ? "allocation: no winner" : "allocation: " + a.award.error().message);
      continue;
    }
    Enqueue(by_id.at(a.award->winners.front()), k);
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
  for (const Task& task : bots_[r].tasks) {
    out_.orders[task.order].failure = why;
    ++terminal_;
  }
  bots_[r].tasks.clear();
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
  StreamOrderOutcome& oc = out_.orders[task.order];
  oc.completed = true;
  oc.completion_time = t;
  ++out_.completed;
  ++terminal_;
  b.tasks.pop_front();
  ctl_.SetLoaded(r, false);
  ctl_.SetIdle(r, b.tasks.empty());
}

void StreamSim::Move(std::size_t r, double t0) {
  Bot& b = bots_[r];
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
      continue;
    }
    if (b.moving) {
      const double rem = (b.len - b.s) / b.speed;
      if (rem <= budget + kTiny) {
        budget -= std::min(rem, budget);
        out_.total_distance += b.len - b.s;
        b.moving = false;
        ctl_.Arrived(r, t0 + (dt - budget));
        continue;
      }
      b.s += budget * b.speed;
      out_.total_distance += budget * b.speed;
      budget = 0;
      if (!b.left_start && b.s >= clearance_) {
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
      } else if (config_.return_home && IsServicePoint(map_->point(b.home).kind)) {
        target = b.home;
      }
      if (target == kNoPoint || (b.tasks.empty() && at == target)) {
        // Idle away from a station: leave service points and corridors to the others.
        if (b.tasks.empty() && config_.idle_step_aside && !b.parked_aside && ctl_.StepAside(r)) {
          b.parked_aside = true;
          continue;
        }
        break;
      }
      if (at == target) {
        b.dwell = b.tasks.front().work;
        ctl_.SetWorking(r, true, now + b.dwell);
        if (b.dwell <= 0) FinishStop(r, now);
        continue;
      }
      auto path = routes_->Path(at, target);
      if (!path.ok()) {
        if (b.tasks.empty()) break;  // cannot get home: stay
        out_.orders[b.tasks.front().order].failure = "unreachable: " + path.error().message;
        ++terminal_;
        b.tasks.pop_front();
        continue;
      }
      (void)ctl_.SetRoute(r, std::move(path->points));
      continue;
    }
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
      continue;
    }
    if (d == TrafficDecision::kReplanned) continue;
    if (d == TrafficDecision::kWait) {
      out_.total_waiting_time += budget;
      if (!b.waiting) ++out_.stops;
      b.waiting = true;
      break;
    }
    // kBlocked: the robot is taken off the floor as faulted (Wang2019: "故障状态").
    const std::string why = b.id + ": " + ctl_.why(r);
    out_.blocked.push_back(why);
    FailTasks(r, "blocked: " + why);
    ctl_.Remove(r);
    b.removed = true;
    b.moving = false;
  }
}

Eigen::Vector2d StreamSim::Position(std::size_t r) const {
  const Bot& b = bots_[r];
  if (b.moving && b.len > 0) return b.from + (b.s / b.len) * (b.to - b.from);
  return map_->point(ctl_.At(r)).position;
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
    if (bots_[r].removed) continue;
    const Eigen::Vector2d p = Position(r);
    const int cx = std::clamp(static_cast<int>((p.x() - origin.x()) / cap), 0, cols_ - 1);
    const int cy = std::clamp(static_cast<int>((p.y() - origin.y()) / cap), 0, rows_ - 1);
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int x = cx + dx, y = cy + dy;
        if (x < 0 || y < 0 || x >= cols_ || y >= rows_) continue;
        const auto cell = static_cast<std::size_t>(y) * static_cast<std::size_t>(cols_) +
                          static_cast<std::size_t>(x);
        if (head_stamp_[cell] != stamp_) continue;
        for (int o = head_[cell]; o >= 0; o = next_in_cell_[static_cast<std::size_t>(o)]) {
          best = std::min(best, (Position(static_cast<std::size_t>(o)) - p).norm());
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
  if (config_.check_safety) {
    SafetyFrame& frame = frames_.emplace_back();
    frame.t = t;
    for (std::size_t r = 0; r < bots_.size(); ++r) {
      if (!bots_[r].removed) frame.robots.push_back({bots_[r].id, bots_[r].id, bots_[r].id, false, Position(r)});
    }
  }
  if (config_.record_series) {
    out_.times.push_back(t);
    out_.min_distance.push_back(best);
  }
}

StreamResult StreamSim::Run() {
  const double dt = config_.time_step;
  std::size_t step = 0;
  double t = 0;
  Sample(0.0);
  while (terminal_ < out_.orders.size() && t < config_.max_time) {
    Release(t);
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
    rules.epsilon_single_single = config_.traffic.point_clearance;
    out_.safety = CheckSafety(frames_, *map_, rules);
  }
  return std::move(out_);
}

}  // namespace

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
  auto ctl = TrafficController::Create(map, tc);
  if (!ctl.ok()) return ctl.error();
  StreamSim sim(map, routes, config, std::move(ctl).value());
  Status init = sim.Init(robots, std::move(orders));
  if (!init.ok()) return init.error();
  return sim.Run();
}

}  // namespace dispatch::engine
