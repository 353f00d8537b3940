#include "engine/dispatch/core_replay.h"

#include <utility>

#include "engine/dispatch/strategy.h"

namespace dispatch::engine {
namespace {

Error Malformed(const JournalEntry& e, const std::string& what) {
  return InvalidArgument("journal entry " + std::to_string(e.seq) + " (" + CoreInputKindName(e.input.kind) +
                         "): " + what);
}

}  // namespace

Result<std::unique_ptr<CoreReplay>> CoreReplay::Create(const ReplaySetup& setup) {
  auto allocator = MakeAllocator(setup.strategy);
  if (!allocator.ok()) return allocator.error();
  auto core = DispatchCore::Create(setup.map, setup.routes, setup.core);
  if (!core.ok()) return core.error();
  auto rounds = std::make_unique<RoundRunner>(setup.map, setup.routes, setup.allocation, std::move(allocator).value());
  return std::unique_ptr<CoreReplay>(new CoreReplay(std::move(core).value(), std::move(rounds)));
}

CoreReplay::CoreReplay(std::unique_ptr<DispatchCore> core, std::unique_ptr<RoundRunner> rounds)
    : core_(std::move(core)), rounds_(std::move(rounds)) {}

CoreReplay::Round* CoreReplay::FindRound(std::uint64_t seq) {
  auto it = round_.find(seq);
  return it == round_.end() ? nullptr : &it->second;
}

void CoreReplay::Observe(const Change& change) {
  for (const OrderChange& line : change.orders) {
    auto it = order_index_.find(line.order_id);
    if (it == order_index_.end() || !line.to) continue;
    OrderTrace& t = orders_[it->second];
    t.state = *line.to;
    if (line.robots) t.robots = *line.robots;
    switch (*line.to) {
      case OrderState::kAssigned:
        t.assigned = change.time;
        break;
      case OrderState::kInProgress:
        t.started = change.time;
        break;
      case OrderState::kCompleted:
        t.finished = change.time;
        break;
      case OrderState::kCancelled:
      case OrderState::kFailed:
        t.finished = change.time;
        t.reason = line.detail;
        break;
      default:
        break;
    }
  }
}

void CoreReplay::Observe(const std::vector<RobotCommand>& messages, double now) {
  for (const RobotCommand& c : messages) {
    const RobotMessage::Kind k = c.message.kind;
    if (k == RobotMessage::Kind::kHold) {
      held_since_.emplace(c.robot, now);
    } else if (k == RobotMessage::Kind::kGrant || k == RobotMessage::Kind::kResume) {
      if (auto it = held_since_.find(c.robot); it != held_since_.end()) {
        hold_seconds_ += now - it->second;
        held_since_.erase(it);
      }
    }
  }
}

Result<std::string> CoreReplay::Feed(const JournalEntry& e) {
  const CoreInput& in = e.input;
  using K = CoreInput::Kind;
  switch (in.kind) {
    case K::kAddOrder: {
      if (!in.order) return Malformed(e, "no order");
      if (!order_index_.count(in.order->id)) {
        OrderTrace t;
        t.id = in.order->id;
        t.formation = in.order->formation;
        t.created = in.order->created_time;
        t.state = in.order->state;
        t.robots = in.robots;
        order_index_[t.id] = orders_.size();
        orders_.push_back(std::move(t));
      }
      core_->AddOrder(*in.order, in.robots);
      return std::string();
    }
    case K::kRestoreRobot:
      if (!in.robot) return Malformed(e, "no robot");
      core_->RestoreRobot(*in.robot, in.plan, in.place, in.marks);
      return std::string();
    case K::kPlace:
      core_->Place(in.robot_id);
      return std::string();
    case K::kConnect:
      if (!in.robot) return Malformed(e, "no robot");
      return DescribeMessages(core_->Connect(*in.robot, in.time));
    case K::kDisconnect:
      core_->Disconnect(in.robot_id);
      return std::string();
    case K::kPlanCommand: {
      if (!in.command) return Malformed(e, "no command");
      Result<Change> out = core_->PlanCommand(*in.command, in.time);
      if (!out.ok()) return "refused: " + out.error().message;
      changes_[e.seq] = *out;
      return DescribeChange(*out);
    }
    case K::kReport:
    case K::kReached: {
      if (in.kind == K::kReport && !in.pose) return Malformed(e, "no pose");
      ReportOutcome out = in.kind == K::kReport
                              ? core_->Report(in.robot_id, *in.pose, in.arc_id, in.state, in.battery, in.sequence, in.time)
                              : core_->Reached(in.robot_id, in.sequence, in.pose, in.time);
      if (out.change) changes_[e.seq] = *out.change;
      return DescribeReport(out);
    }
    case K::kPlanTask: {
      TaskOutcome out = core_->PlanTask(in.robot_id, in.task, in.time);
      if (out.kind == TaskOutcome::Kind::kChange) changes_[e.seq] = out.change;
      return DescribeTask(out);
    }
    case K::kPlanCancel: {
      Result<Change> out = core_->PlanCancel(in.order_id, in.reason, in.time);
      if (!out.ok()) return "error: " + out.error().message;
      changes_[e.seq] = *out;
      return DescribeChange(*out);
    }
    case K::kPlanLoss: {
      Change out = core_->PlanLoss(in.robot_id, in.reason, in.time);
      changes_[e.seq] = out;
      return DescribeChange(out);
    }
    case K::kApply: {
      auto it = changes_.find(in.ref);
      if (it == changes_.end()) return Malformed(e, "no change from entry " + std::to_string(in.ref));
      std::vector<RobotCommand> out = core_->Apply(it->second);
      Observe(it->second);
      Observe(out, it->second.time);
      if (!award_changes_.count(in.ref)) changes_.erase(it);  // PlanAwards' stay for Committed
      return DescribeMessages(out);
    }
    case K::kMakeRound: {
      Round& r = round_[e.seq];
      r.input = core_->MakeRound(in.time, r.commit);
      r.commit.origin = e.seq;
      return DescribeRound(r.input);
    }
    case K::kRoundResult: {
      Round* r = FindRound(in.ref);
      if (!r) return Malformed(e, "no round made at entry " + std::to_string(in.ref));
      r->commit.awards.clear();
      if (!in.cancelled) {
        if (!r->input) return Malformed(e, "the round made at entry " + std::to_string(in.ref) + " had no input");
        RoundResult result = rounds_->Run(*r->input);
        r->commit.awards = std::move(result.awards);
      }
      return DescribeAwards(r->commit.awards);
    }
    case K::kPlanAwards: {
      Round* r = FindRound(in.ref);
      if (!r) return Malformed(e, "no round made at entry " + std::to_string(in.ref));
      Change out = core_->PlanAwards(r->commit, in.max, in.time);
      changes_[e.seq] = out;
      award_changes_.insert(e.seq);
      return DescribeChange(out);
    }
    case K::kCommitted: {
      Round* r = FindRound(in.ref);
      auto it = changes_.find(in.change);
      if (!r || it == changes_.end()) return Malformed(e, "no round or change to commit");
      core_->Committed(r->commit, it->second);
      changes_.erase(it);
      award_changes_.erase(in.change);
      if (r->commit.next >= r->commit.awards.size()) round_.erase(in.ref);
      return std::string();
    }
    case K::kStep: {
      StepOutcome out = core_->Step(in.time);
      Observe(out.messages, in.time);
      return DescribeStep(out);
    }
    case K::kSampleDistances:
      core_->SampleDistances(in.time);
      return std::string();
  }
  return Malformed(e, "unknown kind");
}

}  // namespace dispatch::engine
