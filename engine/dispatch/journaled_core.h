// JournaledCore: a DispatchCore that journals every call changing it (issue 15 §4,
// engine/dispatch/core_journal.h). The owner drives it exactly as it would drive the core; the
// entries collect in memory until TakeEntries (the service writes them to its database after
// every loop batch, the simulator may keep them for a test). CoreReplay feeds them to a fresh
// core again.
//
// Reads of the book go through core(). Changes returned by the Plan* calls carry their entry
// number (Change::origin), rounds theirs (RoundCommit::origin), so Apply and Committed can say
// which call they finish. With recording off the calls go straight through.
//
// Not thread-safe: one owner, as the core.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/dispatch/core_journal.h"
#include "engine/dispatch/dispatch_core.h"

namespace dispatch::engine {

class JournaledCore {
 public:
  JournaledCore(std::unique_ptr<DispatchCore> core, bool recording);

  const DispatchCore& core() const { return *core_; }
  bool recording() const { return recording_; }
  // Stops journaling (e.g. the journal's size limit was reached); calls go on unrecorded.
  void StopRecording() { recording_ = false; }
  // The entries since the last call, in call order.
  std::vector<JournalEntry> TakeEntries();

  // Reads (DispatchCore's), not journaled.
  const BookOrder* order(const std::string& id) const { return core_->order(id); }
  const BookRobot* robot(const std::string& id) const { return core_->robot(id); }
  const std::map<std::string, BookRobot>& robots() const { return core_->robots(); }
  const std::map<std::string, BookOrder>& orders() const { return core_->orders(); }
  const TrafficGate* gate() const { return core_->gate(); }
  const CoreCounts& counts() const { return core_->counts(); }
  std::uint64_t ReleasedUpTo(const std::string& robot) const { return core_->ReleasedUpTo(robot); }
  OrderRoutes RoutesOf(const std::string& order_id) const { return core_->RoutesOf(order_id); }
  PointId TripTo(const std::string& robot) const { return core_->TripTo(robot); }
  bool TakeAllocationDue() { return core_->TakeAllocationDue(); }  // a flag; not journaled

  void AddOrder(Order order, std::vector<std::string> robots = {});
  Result<Change> PlanCancel(const std::string& order_id, const std::string& reason, double now);
  Change PlanLoss(const std::string& robot, const std::string& why, double now);
  std::optional<RoundInput> MakeRound(double now, RoundCommit& commit);
  // The round made by MakeRound (commit.origin) came back with these awards; `cancelled`: it
  // did not run.
  void RoundResult(const RoundCommit& commit, bool cancelled);
  Change PlanAwards(RoundCommit& commit, std::size_t max, double now);
  void Committed(RoundCommit& commit, const Change& change);
  void RestoreRobot(Robot robot, std::optional<Assignment> plan, bool place, OperatorMarks marks = {});
  void Place(const std::string& robot);
  std::vector<RobotCommand> Connect(Robot robot, double now);
  void Disconnect(const std::string& robot);
  ReportOutcome Report(const std::string& robot, const Pose& pose, std::optional<int> arc_id,
                       std::optional<RobotState> state, std::optional<double> battery, std::uint64_t claimed,
                       double now);
  ReportOutcome Reached(const std::string& robot, std::uint64_t seq, const std::optional<Pose>& pose, double now);
  TaskOutcome PlanTask(const std::string& robot, const TaskReport& report, double now);
  Result<Change> PlanCommand(const OperatorCommand& command, double now);
  std::vector<RobotCommand> Apply(const Change& change);
  StepOutcome Step(double now);
  void SampleDistances(double now);

 private:
  // The next entry's number, and the entry itself when recording.
  std::uint64_t Begin();
  void Record(std::uint64_t seq, CoreInput input, std::string output);

  std::unique_ptr<DispatchCore> core_;
  bool recording_;
  std::uint64_t next_seq_ = 1;
  std::vector<JournalEntry> entries_;
};

}  // namespace dispatch::engine
