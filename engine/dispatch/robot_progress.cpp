#include "engine/dispatch/robot_progress.h"

#include <algorithm>

namespace dispatch::engine {

Arrival TakeArrival(RobotProgress& p, const Assignment& a, std::uint64_t seq, std::uint64_t released_up_to,
                    const std::optional<Eigen::Vector2d>& pose, double tolerance) {
  Arrival out;
  out.verdict = CheckReached(a, seq, released_up_to, pose, tolerance);
  if (!out.verdict.taken) return out;
  const Waypoint& w = a.plan.waypoints[out.verdict.index];
  out.fresh = seq > p.last_reached;
  if (out.fresh) {
    out.order = OrderOfWaypoint(a, out.verdict.index, p.order_cursor);
    if (p.last_xy) out.driven = (w.xy - *p.last_xy).norm();
    p.last_xy = w.xy;
    // A new arrival is fresher than the last state report (robots report at a few Hz).
    out.xy = pose ? *pose : w.xy;
    out.retry.swap(p.waiting);
  }
  p.last_reached = std::max(p.last_reached, seq);
  return out;
}

std::vector<TaskReport> TakeStateProgress(RobotProgress& p, const Assignment& a, std::uint64_t claimed,
                                          std::uint64_t* passed) {
  // HighestNumbered(a) >= released_up_to: the plan's last waypoint is read only beyond it.
  bool sent = a.released_up_to >= 0 && claimed <= static_cast<std::uint64_t>(a.released_up_to);
  if (!sent) {
    const std::int64_t numbered = HighestNumbered(a);
    sent = numbered >= 0 && claimed <= static_cast<std::uint64_t>(numbered);
  }
  *passed = sent ? claimed : 0;
  std::vector<TaskReport> retry;
  if (*passed > p.last_reached) retry.swap(p.waiting);
  p.last_reached = std::max(p.last_reached, *passed);
  return retry;
}

TaskVerdict TakeTaskReport(RobotProgress& p, const Assignment& a, const TaskReport& report,
                           const Eigen::Vector2d& robot_xy, double tolerance) {
  TaskVerdict out;
  const ReportVerdict v = CheckTaskEvent(a, report.order_id, report.dropped, p.last_reached, robot_xy, tolerance);
  out.index = v.index;
  out.why = v.why;
  if (v.taken) {
    out.decision = TaskDecision::kTaken;
  } else if (v.later) {
    out.decision = TaskDecision::kWaiting;
    auto same = [&](const TaskReport& e) { return e.order_id == report.order_id && e.dropped == report.dropped; };
    if (std::none_of(p.waiting.begin(), p.waiting.end(), same)) {
      if (p.waiting.size() >= kMaxWaitingReports) {
        p.waiting.erase(p.waiting.begin());
        out.overflowed = true;
      }
      p.waiting.push_back(report);
    }
  }
  return out;
}

DropOutcome PlanDrop(const Assignment& a, const std::string& order_id, const std::string& robot,
                     const std::vector<std::string>& team, const std::set<std::string>& dropped_by) {
  DropOutcome out;
  out.plan = a;
  out.trimmed = TrimDone(out.plan, order_id);
  out.dropped_by = dropped_by;
  out.dropped_by.insert(robot);
  out.complete = out.dropped_by.size() >= team.size();
  return out;
}

}  // namespace dispatch::engine
