#include "engine/sim/core_stream.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <unordered_map>

#include "engine/dispatch/dispatch_core.h"
#include "engine/dispatch/journaled_core.h"
#include "engine/dispatch/strategy.h"
#include "engine/sim/waypoint_robot.h"
#include "engine/traffic/safety_check.h"

namespace dispatch::engine {
namespace {

constexpr double kTiny = 1e-9;

double ReleaseOf(const Order& o) { return o.release_time.value_or(o.created_time); }

class CoreRun {
 public:
  CoreRun(std::shared_ptr<const WarehouseMap> map, const StreamConfig& config, std::unique_ptr<JournaledCore> core,
          std::unique_ptr<RoundRunner> rounds)
      : map_(std::move(map)), config_(config), core_(std::move(core)), rounds_(std::move(rounds)) {}

  std::vector<JournalEntry> TakeJournal() { return core_->TakeEntries(); }

  Status Init(const std::vector<FleetRobot>& robots, std::vector<Order> orders) {
    if (robots.empty()) return InvalidArgument("order stream: no robots");
    std::set<PointId> taken;
    for (const FleetRobot& fr : robots) {
      if (fr.start < 0 || static_cast<std::size_t>(fr.start) >= map_->points().size()) {
        return InvalidArgument("order stream: robot " + fr.id + " starts at an unknown point");
      }
      if (!taken.insert(fr.start).second) {
        return InvalidArgument("order stream: robot " + fr.id + " starts where another robot stands");
      }
      Robot r;
      r.id = fr.id;
      r.kind = fr.kind;
      r.max_speed = config_.allocation.speed;
      r.current_point = fr.start;
      r.pose.position = map_->point(fr.start).position;
      if (auto valid = ValidateRobot(r); !valid.ok()) return valid;
      index_.emplace(fr.id, bots_.size());
      bots_.emplace_back(fr.id, r.pose.position, config_.allocation.speed, config_.allocation.turn_time);
      was_waiting_.push_back(false);
      reported_.emplace_back();
      Deliver(core_->Connect(std::move(r), 0.0));
    }
    std::stable_sort(orders.begin(), orders.end(),
                     [](const Order& a, const Order& b) { return ReleaseOf(a) < ReleaseOf(b); });
    for (const Order& o : orders) {
      if (o.formation && robots.size() < static_cast<std::size_t>(kFormationTeamSize)) {
        return InvalidArgument("order stream: formation order " + o.id + " needs " +
                               std::to_string(kFormationTeamSize) + " robots, the floor has " +
                               std::to_string(robots.size()));
      }
      outcome_of_.emplace(o.id, out_.orders.size());
      StreamOrderOutcome oc;
      oc.order_id = o.id;
      oc.release_time = ReleaseOf(o);
      out_.orders.push_back(oc);
    }
    orders_ = std::move(orders);
    return Ok{};
  }

  StreamResult Run() {
    const double dt = config_.time_step;
    double t = 0.0;
    std::size_t step = 0;
    for (; terminal_ < out_.orders.size() && t <= config_.max_time + kTiny; t = static_cast<double>(++step) * dt) {
      Release(t);
      Allocate(t);
      MoveRobots(t);
      Traffic(t);
      if (config_.check_safety || config_.record_frames) Record(t);
      if (!config_.trace_robots.empty()) Trace(t);
    }
    out_.steps = step;
    out_.end_time = std::min(t, config_.max_time);
    for (const auto& [id, k] : outcome_of_) {
      if (terminal_of_.count(k)) continue;
      Fail(k, "not finished by " + std::to_string(config_.max_time) + " s");
      out_.orders[k].open_at_limit = true;
    }
    Summarise();
    if (config_.check_safety) {
      TrafficConfig rules;
      rules.formation_radius = FormationRadius();
      rules.epsilon_single_single = config_.traffic.point_clearance;
      rules.epsilon_single_formation = rules.epsilon_single_single + rules.formation_radius;
      rules.epsilon_formation_formation = rules.epsilon_single_single + 2.0 * rules.formation_radius;
      SafetyCheckOptions options;
      options.followers_may_diverge = true;  // the controller re-plans inside I_w (as the stream model)
      out_.safety = CheckSafety(frames_, *map_, rules, options);
    }
    if (config_.record_frames) out_.frames = std::move(frames_);
    return std::move(out_);
  }

 private:
  void Release(double t) {
    while (next_release_ < orders_.size() && ReleaseOf(orders_[next_release_]) <= t + kTiny) {
      core_->AddOrder(orders_[next_release_++]);
    }
  }

  void Allocate(double t) {
    if (config_.allocation_period > 0 && t + kTiny < next_allocation_) return;
    if (!core_->TakeAllocationDue() && !again_) return;
    again_ = false;
    if (config_.allocation_period > 0) {
      while (next_allocation_ <= t + kTiny) next_allocation_ += config_.allocation_period;
    }
    RoundCommit commit;
    std::optional<RoundInput> input = core_->MakeRound(t, commit);
    if (!input) return;
    const auto started = std::chrono::steady_clock::now();
    RoundResult round = rounds_->Run(*input);
    out_.planning_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    out_.planned_awards += round.awards.size();
    commit.awards = std::move(round.awards);
    core_->RoundResult(commit, false);
    const Change change = core_->PlanAwards(commit, commit.awards.size(), t);
    again_ = commit.again;
    Commit(change);
  }

  void MoveRobots(double t) {
    std::vector<RobotEvent> events;
    for (std::size_t i = 0; i < bots_.size(); ++i) {
      WaypointRobot& bot = bots_[i];
      events.clear();
      bot.Step(t, events);
      const Pose pose{bot.xy(), bot.heading()};
      for (const RobotEvent& e : events) {
        if (e.kind == RobotEvent::Kind::kReached) {
          Progressed(bot.id(), core_->Reached(bot.id(), e.sequence, pose, t), t);
        } else {
          Task(bot.id(), {e.order_id, e.kind == RobotEvent::Kind::kDropped}, t);
        }
      }
      const bool waiting = !bot.idle() && !bot.moving() && !bot.working();
      if (waiting) out_.total_waiting_time += config_.time_step;
      if (waiting && !was_waiting_[i]) ++out_.stops;
      was_waiting_[i] = waiting;
      const RobotState state = bot.working() ? RobotState::kWorking
                               : bot.moving() ? RobotState::kMoving
                               : waiting      ? RobotState::kWaiting
                                              : RobotState::kIdle;
      // The same report again (pose, state, progress) changes nothing in the core (only the
      // core's Disconnect and a block change a robot's state, and neither happens to a robot
      // that stands still here before it reports again): a robot standing still is not
      // reported again.
      LastReport& last = reported_[i];
      if (last.sent && last.pose.position == pose.position && last.pose.heading == pose.heading &&
          last.state == state && last.reached == bot.last_reached()) {
        continue;
      }
      last = {true, pose, state, bot.last_reached()};
      Progressed(bot.id(), core_->Report(bot.id(), pose, std::nullopt, state, std::nullopt, bot.last_reached(), t), t);
    }
  }

  void Traffic(double t) {
    StepOutcome step = core_->Step(t);
    notes_ = std::move(step.notes);
    Deliver(std::move(step.messages));
    for (const auto& [id, why] : step.blocked) {
      out_.blocked.push_back(id + ": blocked: " + why);
      Commit(core_->PlanLoss(id, "robot " + id + " blocked: " + why, t));
    }
    for (const std::string& id : step.recovered) {
      char at[32];
      std::snprintf(at, sizeof at, " at %.1f s", t);
      out_.recovered.push_back(id + at);
    }
    core_->SampleDistances(t);
    const TrafficGate* gate = core_->gate();
    if (!gate) return;
    const MinDistance& d = gate->min_distance();
    if (d.distance < config_.traffic.point_clearance - 1e-6 && d.distance < last_close_ - 1e-9) {
      last_close_ = d.distance;
      char head[128];
      std::snprintf(head, sizeof head, "%.1f s: %s and %s %.3f m apart: ", d.time, d.a.c_str(), d.b.c_str(), d.distance);
      out_.too_close.push_back(head + gate->Describe(d.a) + " | " + gate->Describe(d.b));
    }
  }

  void Progressed(const std::string& id, ReportOutcome outcome, double t) {
    if (outcome.change) Commit(*outcome.change);
    for (const TaskReport& r : outcome.retry) Task(id, r, t);
  }

  void Task(const std::string& id, const TaskReport& report, double t) {
    TaskOutcome outcome = core_->PlanTask(id, report, t);
    if (outcome.kind == TaskOutcome::Kind::kChange) Commit(outcome.change);
  }

  // The simulator's store: every change is kept (outcomes), then applied.
  void Commit(const Change& change) {
    for (const OrderChange& line : change.orders) {
      auto k = outcome_of_.find(line.order_id);
      if (k == outcome_of_.end() || !line.to) continue;
      StreamOrderOutcome& oc = out_.orders[k->second];
      if (*line.to == OrderState::kAssigned && line.robots && !line.robots->empty()) {
        oc.robot = line.robots->front();
        oc.team = line.robots->size() > 1 ? *line.robots : std::vector<std::string>{};
      } else if (*line.to == OrderState::kCompleted) {
        Complete(k->second, change.time);
      } else if (IsTerminal(*line.to)) {
        Fail(k->second, line.detail);
      }
    }
    Deliver(core_->Apply(change));
  }

  void Deliver(std::vector<RobotCommand> commands) {
    for (RobotCommand& c : commands) {
      if (auto i = index_.find(c.robot); i != index_.end()) bots_[i->second].Apply(c.message);
    }
  }

  void Complete(std::size_t k, double t) {
    if (!terminal_of_.insert(k).second) return;
    out_.orders[k].completed = true;
    out_.orders[k].completion_time = t;
    ++out_.completed;
    ++terminal_;
  }

  void Fail(std::size_t k, const std::string& why) {
    if (!terminal_of_.insert(k).second) return;
    out_.orders[k].failure = why;
    ++terminal_;
  }

  // Where every robot really is (not where the gate believes it is), tagged with what the
  // gate makes of it: a formation member moves with its team's agent once that agent stands
  // for it in the controller (not while it still drives to its slot on its own agent), and is
  // exempt from its teammates from the approach to its slot until it has driven off after the
  // drop.
  void Record(double t) {
    SafetyFrame& frame = frames_.emplace_back();
    frame.t = t;
    const TrafficGate* gate = core_->gate();
    for (const WaypointRobot& b : bots_) {
      const GateRobotState s = gate ? gate->RobotState(b.id()) : GateRobotState{};
      auto group = [&](std::size_t k) { return s.teams[k].empty() ? std::string() : "team " + s.teams[k]; };
      frame.robots.push_back({b.id(), s.moved_by_team ? "formation " + s.formation : b.id(),
                              s.teams[0].empty() ? b.id() : group(0), s.moved_by_team, b.xy(), group(1), group(2)});
    }
  }

  // StreamConfig::trace_robots: where each traced robot really is and what the gate makes of
  // it, and the gate's notes, at every step of the window.
  void Trace(double t) {
    if (t + kTiny < config_.trace_from || t - kTiny > config_.trace_to) return;
    char head[96];
    for (const std::string& n : notes_) {
      std::snprintf(head, sizeof head, "%.1f s: note: ", t);
      out_.trace.push_back(head + n);
    }
    const TrafficGate* gate = core_->gate();
    for (const std::string& id : config_.trace_robots) {
      auto i = index_.find(id);
      if (i == index_.end()) continue;
      const WaypointRobot& b = bots_[i->second];
      std::snprintf(head, sizeof head, "%.1f s: %s at (%.3f, %.3f) %s, reached %llu: ", t, id.c_str(), b.xy().x(),
                    b.xy().y(), b.working() ? "working" : b.moving() ? "moving" : b.idle() ? "idle" : "waiting",
                    static_cast<unsigned long long>(b.last_reached()));
      out_.trace.push_back(head + (gate ? gate->Describe(id) : std::string("no traffic control")));
    }
  }

  void Summarise() {
    double sum = 0.0;
    for (const StreamOrderOutcome& oc : out_.orders) {
      if (!oc.completed) continue;
      out_.makespan = std::max(out_.makespan, oc.completion_time);
      sum += oc.completion_time - oc.release_time;
    }
    if (out_.completed > 0) out_.mean_completion = sum / static_cast<double>(out_.completed);
    if (out_.makespan > 0) out_.throughput_per_hour = static_cast<double>(out_.completed) / out_.makespan * 3600.0;
    for (const WaypointRobot& b : bots_) out_.total_distance += b.driven();
    if (const TrafficGate* gate = core_->gate()) {
      out_.traffic = gate->stats();
      const MinDistance& d = gate->min_distance();
      out_.overall_min_distance = d.distance;
      if (!d.a.empty()) out_.min_pair = d.a + " " + d.b;
      out_.min_time = d.time;
    }
  }

  std::shared_ptr<const WarehouseMap> map_;
  const StreamConfig& config_;
  std::unique_ptr<JournaledCore> core_;
  std::unique_ptr<RoundRunner> rounds_;
  std::vector<WaypointRobot> bots_;
  std::unordered_map<std::string, std::size_t> index_;
  std::vector<bool> was_waiting_;
  struct LastReport {
    bool sent = false;
    Pose pose;
    RobotState state = RobotState::kIdle;
    std::uint64_t reached = 0;
  };
  std::vector<LastReport> reported_;  // each robot's last state report
  std::vector<SafetyFrame> frames_;    // check_safety, record_frames
  std::vector<std::string> notes_;     // the gate's notes of the current step (Trace)
  std::vector<Order> orders_;  // by release time
  std::size_t next_release_ = 0;
  double next_allocation_ = 0.0;
  bool again_ = false;
  double last_close_ = std::numeric_limits<double>::infinity();  // closest pair below eps1 so far
  std::unordered_map<std::string, std::size_t> outcome_of_;
  std::set<std::size_t> terminal_of_;
  std::size_t terminal_ = 0;
  StreamResult out_;
};

}  // namespace

CoreOptions CoreOptionsOf(const StreamConfig& config) {
  CoreOptions options;
  options.traffic = config.traffic;
  options.traffic.speed = config.allocation.speed;
  options.one_formation_per_pick = config.one_formation_per_pick;
  options.blocked_recovery = config.blocked_recovery;
  return options;
}

Result<StreamResult> SimulateOnCore(std::shared_ptr<const WarehouseMap> map, std::shared_ptr<const RouteTable> routes,
                                    const std::vector<FleetRobot>& robots, std::vector<Order> orders,
                                    const StreamConfig& config, std::vector<JournalEntry>* journal) {
  if (!map || !routes) return InvalidArgument("order stream: no map or route table");
  if (!(config.time_step > 0) || !std::isfinite(config.time_step) || !(config.max_time > 0) ||
      !(config.allocation_period >= 0)) {
    return InvalidArgument("order stream: time_step and max_time must be > 0");
  }
  if (auto valid = ValidateAllocationConfig(config.allocation); !valid.ok()) return valid.error();
  auto allocator = MakeAllocator(AllocationStrategyName(config.strategy));
  if (!allocator.ok()) return allocator.error();
  auto rounds = std::make_unique<RoundRunner>(map, routes, config.allocation, std::move(allocator).value());
  auto core = DispatchCore::Create(map, routes, CoreOptionsOf(config));
  if (!core.ok()) return core.error();
  CoreRun run(map, config, std::make_unique<JournaledCore>(std::move(core).value(), journal != nullptr),
              std::move(rounds));
  if (auto init = run.Init(robots, std::move(orders)); !init.ok()) return init.error();
  StreamResult result = run.Run();
  if (journal) *journal = run.TakeJournal();
  return result;
}

}  // namespace dispatch::engine
