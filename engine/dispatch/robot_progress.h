// A robot's progress through its plan as the dispatch book keeps it (issue 15 §1): what it
// reported reaching, where, the metres it drove per order, and the picks and drops it
// reported before reaching them. Each report goes through the plausibility checks of
// report_check.h; the functions here say what the report changes, and the owner carries out
// the rest (the gate, the order's state, the store).
//
// Values and free functions; not thread-safe to mutate concurrently.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "engine/dispatch/assignment.h"
#include "engine/dispatch/report_check.h"

namespace dispatch::engine {

// "Picked" / "dropped" for an order, as a robot reported it.
struct TaskReport {
  std::string order_id;
  bool dropped = false;  // false: picked
};

struct RobotProgress {
  std::uint64_t last_reached = 0;        // highest waypoint sequence reached
  std::optional<Eigen::Vector2d> last_xy;  // where it reached its last waypoint (distances)
  std::vector<TaskReport> waiting;       // reported before reached: tried again on progress
  OrderCursor order_cursor;              // the order of its last arrival (TakeArrival)
};

// Picks and drops that may wait for a robot's progress (the oldest is dropped beyond it).
inline constexpr std::size_t kMaxWaitingReports = 8;

struct Arrival {
  ReportVerdict verdict;  // not taken: nothing changed
  bool fresh = false;     // a new arrival (not a repeat of an older one)
  // Fresh arrivals: where the robot is seen from now (its pose, else the waypoint's), the
  // order the waypoint serves and the metres driven for it since the previous arrival.
  std::optional<Eigen::Vector2d> xy;
  std::string order;
  double driven = 0.0;
  std::vector<TaskReport> retry;  // fresh arrivals: the waiting reports, to try again
};

// "Reached waypoint `seq`" (CheckReached against `released_up_to`).
Arrival TakeArrival(RobotProgress& p, const Assignment& a, std::uint64_t seq, std::uint64_t released_up_to,
                    const std::optional<Eigen::Vector2d>& pose, double tolerance);

// A state report's "last waypoint passed": taken up to the highest sequence ever numbered for
// the robot (a waypoint never sent cannot have been passed; 0 beyond it). Returns the waiting
// reports to try again when it progressed, and sets *passed to the sequence taken.
std::vector<TaskReport> TakeStateProgress(RobotProgress& p, const Assignment& a, std::uint64_t claimed,
                                          std::uint64_t* passed);

enum class TaskDecision { kTaken, kWaiting, kRejected };
struct TaskVerdict {
  TaskDecision decision = TaskDecision::kRejected;
  std::size_t index = 0;  // kTaken: the stop's waypoint index
  std::string why;        // kWaiting, kRejected
  bool overflowed = false;  // kWaiting: the oldest waiting report was dropped to make room
};

// A pick or drop report (CheckTaskEvent with where the robot was last seen); a report of a
// stop not reached yet waits (once per order and kind).
TaskVerdict TakeTaskReport(RobotProgress& p, const Assignment& a, const TaskReport& report,
                           const Eigen::Vector2d& robot_xy, double tolerance);

// A member's drop of `order_id` (served by `team`; `dropped_by` the members that dropped
// before): the robot's plan without the finished order, and whether the order is complete.
struct DropOutcome {
  Assignment plan;
  bool trimmed = false;  // the order was the plan's first and is gone from it
  std::set<std::string> dropped_by;
  bool complete = false;  // every member dropped
};
DropOutcome PlanDrop(const Assignment& a, const std::string& order_id, const std::string& robot,
                     const std::vector<std::string>& team, const std::set<std::string>& dropped_by);

}  // namespace dispatch::engine
