#include "engine/dispatch/core_journal.h"

#include <array>
#include <cstdio>
#include <cstring>
#include <limits>
#include <utility>

#include "engine/common/fnv1a.h"

namespace dispatch::engine {
namespace {

constexpr std::array<std::pair<CoreInput::Kind, const char*>, 18> kKinds{{
    {CoreInput::Kind::kAddOrder, "add_order"},
    {CoreInput::Kind::kRestoreRobot, "restore_robot"},
    {CoreInput::Kind::kPlace, "place"},
    {CoreInput::Kind::kConnect, "connect"},
    {CoreInput::Kind::kDisconnect, "disconnect"},
    {CoreInput::Kind::kReport, "report"},
    {CoreInput::Kind::kReached, "reached"},
    {CoreInput::Kind::kPlanTask, "plan_task"},
    {CoreInput::Kind::kPlanCancel, "plan_cancel"},
    {CoreInput::Kind::kPlanLoss, "plan_loss"},
    {CoreInput::Kind::kApply, "apply"},
    {CoreInput::Kind::kMakeRound, "make_round"},
    {CoreInput::Kind::kRoundResult, "round_result"},
    {CoreInput::Kind::kPlanAwards, "plan_awards"},
    {CoreInput::Kind::kCommitted, "committed"},
    {CoreInput::Kind::kStep, "step"},
    {CoreInput::Kind::kSampleDistances, "sample_distances"},
    {CoreInput::Kind::kPlanCommand, "plan_command"},
}};

std::string Join(const std::vector<std::string>& items, const char* sep) {
  std::string out;
  for (const std::string& s : items) {
    if (!out.empty()) out += sep;
    out += s;
  }
  return out;
}

void Add(std::string& out, const std::string& part) {
  if (part.empty()) return;
  if (!out.empty()) out += "; ";
  out += part;
}

// The waypoints as numbers: a plan's identity without printing it whole. A posed waypoint's
// heading and motion mode count too (four-wheel-steer plans); a waypoint without them adds the
// bytes it always did, so journals of lane plans replay to the same lines.
std::string WaypointsDigest(const std::vector<Waypoint>& waypoints) {
  std::string bytes;
  for (const Waypoint& w : waypoints) {
    const double values[] = {w.xy.x(), w.xy.y(), w.eta, w.dwell};
    const int ints[] = {w.seq, w.point, static_cast<int>(w.action)};
    bytes.append(reinterpret_cast<const char*>(values), sizeof(values));
    bytes.append(reinterpret_cast<const char*>(ints), sizeof(ints));
    if (w.heading || w.mode) {
      const double heading = w.heading.value_or(std::numeric_limits<double>::quiet_NaN());
      const int mode = w.mode ? static_cast<int>(*w.mode) : -1;
      bytes.append(reinterpret_cast<const char*>(&heading), sizeof(heading));
      bytes.append(reinterpret_cast<const char*>(&mode), sizeof(mode));
    }
  }
  return Hex64(Fnv1a64(bytes)).substr(0, 8);
}

std::string DescribeMessage(const RobotCommand& c) {
  const RobotMessage& m = c.message;
  std::vector<MessageWaypoint>::size_type n = m.waypoints.size();
  std::vector<Waypoint> wps;
  for (const MessageWaypoint& w : m.waypoints) wps.push_back(w.waypoint);
  char buf[160];
  switch (m.kind) {
    case RobotMessage::Kind::kWelcome:
      return c.robot + " welcome";
    case RobotMessage::Kind::kAssignment:
      std::snprintf(buf, sizeof buf, " assignment p%llu %zu wp r%llu #%s [",
                    static_cast<unsigned long long>(m.plan_id), n,
                    static_cast<unsigned long long>(m.released_up_to), WaypointsDigest(wps).c_str());
      return c.robot + buf + Join(m.order_ids, ",") + "]";
    case RobotMessage::Kind::kPlanUpdate:
      std::snprintf(buf, sizeof buf, " update p%llu from %llu %zu wp r%llu #%s",
                    static_cast<unsigned long long>(m.plan_id),
                    static_cast<unsigned long long>(m.from_sequence), n,
                    static_cast<unsigned long long>(m.released_up_to), WaypointsDigest(wps).c_str());
      return c.robot + buf;
    case RobotMessage::Kind::kCancel:
      return c.robot + " cancel [" + Join(m.order_ids, ",") + "] " + m.reason;
    case RobotMessage::Kind::kGrant:
      std::snprintf(buf, sizeof buf, " grant %llu i%d", static_cast<unsigned long long>(m.released_up_to),
                    m.intersection_id);
      return c.robot + buf;
    case RobotMessage::Kind::kHold:
      std::snprintf(buf, sizeof buf, " hold at %llu: ", static_cast<unsigned long long>(m.stop_at_sequence));
      return c.robot + buf + m.reason;
    case RobotMessage::Kind::kResume:
      std::snprintf(buf, sizeof buf, " resume %llu", static_cast<unsigned long long>(m.released_up_to));
      return c.robot + buf;
  }
  return c.robot + " ?";
}

}  // namespace

const char* CoreInputKindName(CoreInput::Kind kind) {
  for (const auto& [k, name] : kKinds) {
    if (k == kind) return name;
  }
  return "?";
}

std::optional<CoreInput::Kind> ParseCoreInputKind(const std::string& name) {
  for (const auto& [k, n] : kKinds) {
    if (name == n) return k;
  }
  if (name == "pause") return CoreInput::Kind::kPlanCommand;  // journals before "plan_command"
  return std::nullopt;
}

std::string DescribeMessages(const std::vector<RobotCommand>& commands) {
  std::string out;
  for (const RobotCommand& c : commands) Add(out, DescribeMessage(c));
  return out;
}

std::string DescribeChange(const Change& change) {
  std::string out;
  for (const OrderChange& line : change.orders) {
    std::string s = line.order_id;
    if (line.to) {
      s += std::string(" -> ") + OrderStateName(*line.to);
      if (line.robots) s += " [" + Join(*line.robots, ",") + "]";
      if (*line.to == OrderState::kCancelled || *line.to == OrderState::kFailed) s += ": " + line.detail;
    } else {
      s += " note";
    }
    Add(out, s);
  }
  for (const auto& [robot, plan] : change.plans) {
    char buf[96];
    std::snprintf(buf, sizeof buf, " plan p%llu %zu wp #%s", static_cast<unsigned long long>(plan.plan_id),
                  plan.plan.waypoints.size(), WaypointsDigest(plan.plan.waypoints).c_str());
    Add(out, robot + buf + " [" + Join(plan.order_ids, ",") + "]");
  }
  for (const auto& [order, members] : change.dropped_by) {
    Add(out, order + " dropped by " + Join(std::vector<std::string>(members.begin(), members.end()), ","));
  }
  for (const auto& [robot, marks] : change.marks) {
    std::string s = robot + " marks:";
    if (!marks.paused_by.empty()) s += " paused by " + marks.paused_by;
    if (!marks.out_of_service_by.empty()) s += " out of service by " + marks.out_of_service_by;
    if (marks.off_floor) s += " off the floor";
    if (marks == OperatorMarks{}) s += " none";
    Add(out, s);
  }
  return out;
}

std::string DescribeReport(const ReportOutcome& outcome) {
  std::string out;
  if (!outcome.taken) Add(out, "not taken: " + outcome.why);
  if (outcome.change) Add(out, DescribeChange(*outcome.change));
  for (const TaskReport& r : outcome.retry) Add(out, std::string("retry ") + (r.dropped ? "drop " : "pick ") + r.order_id);
  return out;
}

std::string DescribeTask(const TaskOutcome& outcome) {
  switch (outcome.kind) {
    case TaskOutcome::Kind::kIgnored:
      return "ignored";
    case TaskOutcome::Kind::kWaiting:
      return "waiting: " + outcome.what + ": " + outcome.why;
    case TaskOutcome::Kind::kImplausible:
      return "implausible: " + outcome.what + ": " + outcome.why;
    case TaskOutcome::Kind::kChange:
      return DescribeChange(outcome.change);
  }
  return "?";
}

std::string DescribeStep(const StepOutcome& outcome) {
  std::string out = DescribeMessages(outcome.messages);
  for (const Assignment& a : outcome.rewritten) {
    Add(out, a.robot_id + " rewritten p" + std::to_string(a.plan_id) + " #" + WaypointsDigest(a.plan.waypoints));
  }
  for (const auto& [robot, why] : outcome.blocked) Add(out, robot + " blocked: " + why);
  return out;
}

std::string DescribeRound(const std::optional<RoundInput>& input) {
  if (!input) return "";
  std::vector<std::string> robots, orders;
  for (const RoundRobot& r : input->robots) robots.push_back(r.id + "@" + std::to_string(r.start));
  for (const auto& o : input->pending) orders.push_back(o->id);
  return "robots " + Join(robots, ",") + " orders " + Join(orders, ",");
}

std::string DescribeAwards(const std::vector<RoundAward>& awards) {
  std::string out;
  for (const RoundAward& a : awards) {
    std::vector<std::vector<Waypoint>>::size_type n = a.segments.size();
    std::vector<Waypoint> all;
    for (const auto& segment : a.segments) all.insert(all.end(), segment.begin(), segment.end());
    Add(out, a.order_id + " [" + Join(a.award.winners, ",") + "] " + std::to_string(n) + " seg #" +
                 WaypointsDigest(all) + " " + a.award.reason);
  }
  return out;
}

}  // namespace dispatch::engine
