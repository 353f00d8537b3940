#include "server/robot_sessions.h"

#include <algorithm>
#include <utility>

namespace dispatch::server {

RobotSession* RobotSessions::Find(const std::string& robot_id) {
  auto it = sessions_.find(robot_id);
  return it == sessions_.end() ? nullptr : &it->second;
}

const RobotSession* RobotSessions::Find(const std::string& robot_id) const {
  auto it = sessions_.find(robot_id);
  return it == sessions_.end() ? nullptr : &it->second;
}

const std::string* RobotSessions::RobotOf(const RobotLink* link) const {
  auto it = link_robot_.find(link);
  return it == link_robot_.end() ? nullptr : &it->second;
}

void RobotSessions::Attach(const std::string& robot_id, std::shared_ptr<RobotLink> link) {
  link_robot_[link.get()] = robot_id;
  sessions_[robot_id].link = std::move(link);
}

std::shared_ptr<RobotLink> RobotSessions::Detach(const std::string& robot_id) {
  RobotSession* s = Find(robot_id);
  if (!s || !s->link) return nullptr;
  link_robot_.erase(s->link.get());
  return std::exchange(s->link, nullptr);
}

std::optional<double> TrackHold(RobotSession& session, RobotOutbound::Kind kind, double now) {
  using Kind = RobotOutbound::Kind;
  if (kind == Kind::kHold) {
    if (!session.held_since) session.held_since = now;
    return std::nullopt;
  }
  if (kind != Kind::kGrant && kind != Kind::kResume) return std::nullopt;
  const std::optional<double> held_since = std::exchange(session.held_since, std::nullopt);
  if (!held_since) return std::nullopt;
  return now - *held_since;
}

storage::RobotRecord RecordOf(const engine::BookRobot* robot, const RobotSession* session) {
  storage::RobotRecord rec;
  if (robot) {
    rec.robot = robot->robot;
    rec.marks = robot->marks;
  }
  if (session) {
    rec.kind = session->kind;
    rec.last_seen = session->last_seen;
    rec.last_acked_sequence = session->last_acked_sequence;
    rec.next_sequence = session->next_sequence;
  }
  return rec;
}

void RestoreSession(RobotSession& session, const storage::RobotRecord& record) {
  session.kind = record.kind;
  session.last_seen = record.last_seen;
  session.last_acked_sequence = record.last_acked_sequence;
  session.next_sequence = record.next_sequence;
}

storage::RobotRecord HelloRecord(storage::RobotRecord record, const RobotInbound& hello, engine::PointId point,
                                 double default_speed, double now) {
  record.robot.id = hello.robot_id;
  if (hello.diameter > 0) record.robot.diameter = hello.diameter;
  record.robot.max_speed = hello.max_speed > 0 ? hello.max_speed : default_speed;
  record.robot.pose = hello.pose;
  record.robot.current_point = point;
  record.robot.state = engine::RobotState::kIdle;
  record.marks.off_floor = false;  // a Hello puts a robot cleared off the floor back on it
  if (record.robot.battery && !(*record.robot.battery >= 0.0 && *record.robot.battery <= 1.0)) {
    record.robot.battery.reset();  // stored by an older server that took any report
  }
  record.kind = hello.robot_kind.empty() ? "differential" : hello.robot_kind;
  record.robot.kind = engine::ParseRobotKind(record.kind).value_or(engine::RobotKind::kDifferential);
  record.last_seen = now;
  record.last_acked_sequence = std::max(record.last_acked_sequence, hello.last_acked_sequence);
  if (record.next_sequence <= record.last_acked_sequence) record.next_sequence = record.last_acked_sequence + 1;
  return record;
}

}  // namespace dispatch::server
