#include "engine/dispatch/journaled_core.h"

#include <utility>

namespace dispatch::engine {

JournaledCore::JournaledCore(std::unique_ptr<DispatchCore> core, bool recording)
    : core_(std::move(core)), recording_(recording) {}

std::vector<JournalEntry> JournaledCore::TakeEntries() {
  std::vector<JournalEntry> out;
  out.swap(entries_);
  return out;
}

std::uint64_t JournaledCore::Begin() { return next_seq_++; }

void JournaledCore::Record(std::uint64_t seq, CoreInput input, std::string output) {
  if (!recording_) return;
  entries_.push_back(JournalEntry{seq, std::move(input), std::move(output)});
}

void JournaledCore::AddOrder(Order order, std::vector<std::string> robots) {
  const std::uint64_t seq = Begin();
  CoreInput in;
  in.kind = CoreInput::Kind::kAddOrder;
  if (recording_) {
    in.order = order;
    in.robots = robots;
  }
  core_->AddOrder(std::move(order), std::move(robots));
  Record(seq, std::move(in), "");
}

Result<Change> JournaledCore::PlanCancel(const std::string& order_id, const std::string& reason, double now) {
  const std::uint64_t seq = Begin();
  Result<Change> out = core_->PlanCancel(order_id, reason, now);
  if (out.ok()) out.value().origin = seq;
  CoreInput in;
  in.kind = CoreInput::Kind::kPlanCancel;
  in.time = now;
  in.order_id = order_id;
  in.reason = reason;
  Record(seq, std::move(in), out.ok() ? DescribeChange(*out) : "error: " + out.error().message);
  return out;
}

Change JournaledCore::PlanLoss(const std::string& robot, const std::string& why, double now) {
  const std::uint64_t seq = Begin();
  Change out = core_->PlanLoss(robot, why, now);
  out.origin = seq;
  CoreInput in;
  in.kind = CoreInput::Kind::kPlanLoss;
  in.time = now;
  in.robot_id = robot;
  in.reason = why;
  Record(seq, std::move(in), DescribeChange(out));
  return out;
}

std::optional<RoundInput> JournaledCore::MakeRound(double now, RoundCommit& commit) {
  const std::uint64_t seq = Begin();
  std::optional<RoundInput> out = core_->MakeRound(now, commit);
  commit.origin = seq;
  CoreInput in;
  in.kind = CoreInput::Kind::kMakeRound;
  in.time = now;
  Record(seq, std::move(in), recording_ ? DescribeRound(out) : "");
  return out;
}

void JournaledCore::RoundResult(const RoundCommit& commit, bool cancelled) {
  const std::uint64_t seq = Begin();
  CoreInput in;
  in.kind = CoreInput::Kind::kRoundResult;
  in.ref = commit.origin;
  in.cancelled = cancelled;
  Record(seq, std::move(in), recording_ ? DescribeAwards(commit.awards) : "");
}

Change JournaledCore::PlanAwards(RoundCommit& commit, std::size_t max, double now) {
  const std::uint64_t seq = Begin();
  Change out = core_->PlanAwards(commit, max, now);
  out.origin = seq;
  CoreInput in;
  in.kind = CoreInput::Kind::kPlanAwards;
  in.time = now;
  in.ref = commit.origin;
  in.max = max;
  Record(seq, std::move(in), recording_ ? DescribeChange(out) : "");
  return out;
}

void JournaledCore::Committed(RoundCommit& commit, const Change& change) {
  const std::uint64_t seq = Begin();
  core_->Committed(commit, change);
  CoreInput in;
  in.kind = CoreInput::Kind::kCommitted;
  in.ref = commit.origin;
  in.change = change.origin;
  Record(seq, std::move(in), "");
}

void JournaledCore::RestoreRobot(Robot robot, std::optional<Assignment> plan, bool place, OperatorMarks marks) {
  const std::uint64_t seq = Begin();
  CoreInput in;
  in.kind = CoreInput::Kind::kRestoreRobot;
  if (recording_) {
    in.robot = robot;
    in.plan = plan;
  }
  in.place = place;
  in.marks = marks;
  core_->RestoreRobot(std::move(robot), std::move(plan), place, std::move(marks));
  Record(seq, std::move(in), "");
}

void JournaledCore::Place(const std::string& robot) {
  const std::uint64_t seq = Begin();
  core_->Place(robot);
  CoreInput in;
  in.kind = CoreInput::Kind::kPlace;
  in.robot_id = robot;
  Record(seq, std::move(in), "");
}

std::vector<RobotCommand> JournaledCore::Connect(Robot robot, double now) {
  const std::uint64_t seq = Begin();
  CoreInput in;
  in.kind = CoreInput::Kind::kConnect;
  in.time = now;
  if (recording_) in.robot = robot;
  std::vector<RobotCommand> out = core_->Connect(std::move(robot), now);
  Record(seq, std::move(in), recording_ ? DescribeMessages(out) : "");
  return out;
}

Result<Change> JournaledCore::PlanCommand(const OperatorCommand& command, double now) {
  const std::uint64_t seq = Begin();
  Result<Change> out = core_->PlanCommand(command, now);
  if (out.ok()) out.value().origin = seq;
  CoreInput in;
  in.kind = CoreInput::Kind::kPlanCommand;
  in.time = now;
  in.robot_id = command.robot;
  in.command = command;
  Record(seq, std::move(in), out.ok() ? DescribeChange(*out) : "refused: " + out.error().message);
  return out;
}

void JournaledCore::Disconnect(const std::string& robot) {
  const std::uint64_t seq = Begin();
  core_->Disconnect(robot);
  CoreInput in;
  in.kind = CoreInput::Kind::kDisconnect;
  in.robot_id = robot;
  Record(seq, std::move(in), "");
}

ReportOutcome JournaledCore::Report(const std::string& robot, const Pose& pose, std::optional<int> arc_id,
                                    std::optional<RobotState> state, std::optional<double> battery,
                                    std::uint64_t claimed, double now) {
  const std::uint64_t seq = Begin();
  ReportOutcome out = core_->Report(robot, pose, arc_id, state, battery, claimed, now);
  if (out.change) out.change->origin = seq;
  if (!recording_) return out;  // the most frequent call: no input built for nothing
  CoreInput in;
  in.kind = CoreInput::Kind::kReport;
  in.time = now;
  in.robot_id = robot;
  in.pose = pose;
  in.arc_id = arc_id;
  in.state = state;
  in.battery = battery;
  in.sequence = claimed;
  Record(seq, std::move(in), DescribeReport(out));
  return out;
}

ReportOutcome JournaledCore::Reached(const std::string& robot, std::uint64_t waypoint,
                                     const std::optional<Pose>& pose, double now) {
  const std::uint64_t seq = Begin();
  ReportOutcome out = core_->Reached(robot, waypoint, pose, now);
  if (out.change) out.change->origin = seq;
  if (!recording_) return out;
  CoreInput in;
  in.kind = CoreInput::Kind::kReached;
  in.time = now;
  in.robot_id = robot;
  in.sequence = waypoint;
  in.pose = pose;
  Record(seq, std::move(in), DescribeReport(out));
  return out;
}

TaskOutcome JournaledCore::PlanTask(const std::string& robot, const TaskReport& report, double now) {
  const std::uint64_t seq = Begin();
  TaskOutcome out = core_->PlanTask(robot, report, now);
  out.change.origin = seq;
  CoreInput in;
  in.kind = CoreInput::Kind::kPlanTask;
  in.time = now;
  in.robot_id = robot;
  in.task = report;
  Record(seq, std::move(in), recording_ ? DescribeTask(out) : "");
  return out;
}

std::vector<RobotCommand> JournaledCore::Apply(const Change& change) {
  const std::uint64_t seq = Begin();
  std::vector<RobotCommand> out = core_->Apply(change);
  CoreInput in;
  in.kind = CoreInput::Kind::kApply;
  in.ref = change.origin;
  Record(seq, std::move(in), recording_ ? DescribeMessages(out) : "");
  return out;
}

StepOutcome JournaledCore::Step(double now) {
  const std::uint64_t seq = Begin();
  StepOutcome out = core_->Step(now);
  CoreInput in;
  in.kind = CoreInput::Kind::kStep;
  in.time = now;
  Record(seq, std::move(in), recording_ ? DescribeStep(out) : "");
  return out;
}

void JournaledCore::SampleDistances(double now) {
  const std::uint64_t seq = Begin();
  core_->SampleDistances(now);
  CoreInput in;
  in.kind = CoreInput::Kind::kSampleDistances;
  in.time = now;
  Record(seq, std::move(in), "");
}

}  // namespace dispatch::engine
