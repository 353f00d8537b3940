// The dispatch core's journal (issue 15 §4): every call that changes the core, as a value,
// with what the call gave back in one line of text, so that a recorded run can be fed through
// a fresh core again (CoreReplay) and compared call by call.
//
// An entry is one call of DispatchCore (AddOrder, RestoreRobot, Place, Connect, Disconnect,
// Report, Reached, PlanTask, PlanCancel, PlanLoss, Apply, MakeRound, PlanAwards, Committed,
// Step, SampleDistances, PlanCommand) or the result of an allocation round coming back (kRoundResult: the
// round runs outside the core, on the service's worker). Calls that refer to an earlier one
// carry its entry number: Apply the entry whose Change it applies, PlanAwards / Committed /
// kRoundResult the MakeRound of their round (Change::origin, RoundCommit::origin).
//
// The output line (Describe*) names what the call decided: order transitions with their
// robots, plans stored, robot messages (assignments, plan updates, cancels, grants with their
// horizon, holds with their reason, resumes), robots found blocked, round inputs and awards.
// Reads of the book are not journaled: they change nothing.
//
// Plain values and pure functions.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "engine/dispatch/allocation_round.h"
#include "engine/dispatch/assignment.h"
#include "engine/dispatch/dispatch_core.h"
#include "engine/dispatch/robot_progress.h"
#include "engine/fleet/order.h"
#include "engine/fleet/robot.h"

namespace dispatch::engine {

struct CoreInput {
  enum class Kind {
    kAddOrder,
    kRestoreRobot,
    kPlace,
    kConnect,
    kDisconnect,
    kReport,
    kReached,
    kPlanTask,
    kPlanCancel,
    kPlanLoss,
    kApply,
    kMakeRound,
    kRoundResult,
    kPlanAwards,
    kCommitted,
    kStep,
    kSampleDistances,
    kPlanCommand,  // an operator's command on a robot (command)
  };
  Kind kind = Kind::kStep;
  double time = 0.0;      // the call's `now` (0 for calls without one)
  std::string robot_id;   // Place, Disconnect, Report, Reached, PlanTask, PlanLoss
  std::string order_id;   // PlanCancel
  std::string reason;     // PlanCancel, PlanLoss
  std::optional<Order> order;          // AddOrder
  std::vector<std::string> robots;     // AddOrder: the robots a recovered order has
  std::optional<Robot> robot;          // RestoreRobot, Connect
  std::optional<Assignment> plan;      // RestoreRobot
  bool place = false;                  // RestoreRobot
  OperatorMarks marks;                 // RestoreRobot
  std::optional<OperatorCommand> command;  // PlanCommand
  std::optional<Pose> pose;            // Report (always), Reached (when sent)
  std::optional<int> arc_id;           // Report
  std::optional<RobotState> state;     // Report
  std::optional<double> battery;       // Report
  std::uint64_t sequence = 0;          // Report: claimed; Reached: the waypoint reached
  TaskReport task;                     // PlanTask
  std::uint64_t ref = 0;     // Apply: the change's entry; PlanAwards/Committed/RoundResult: MakeRound's
  std::uint64_t change = 0;  // Committed: the PlanAwards entry whose change was committed
  std::size_t max = 0;       // PlanAwards
  bool cancelled = false;    // RoundResult: the round did not run (the service stopped)
};

// "add_order", "restore_robot", "place", "connect", ... (the journal's kind column).
const char* CoreInputKindName(CoreInput::Kind kind);
std::optional<CoreInput::Kind> ParseCoreInputKind(const std::string& name);

struct JournalEntry {
  std::uint64_t seq = 0;  // 1, 2, ... within a run
  CoreInput input;
  std::string output;     // Describe* of what the call returned ("" = nothing)
};

// One line per kind of result; "" when there is nothing to say.
std::string DescribeMessages(const std::vector<RobotCommand>& commands);
std::string DescribeChange(const Change& change);
std::string DescribeReport(const ReportOutcome& outcome);
std::string DescribeTask(const TaskOutcome& outcome);
std::string DescribeStep(const StepOutcome& outcome);
std::string DescribeRound(const std::optional<RoundInput>& input);
std::string DescribeAwards(const std::vector<RoundAward>& awards);

}  // namespace dispatch::engine
