#include "server/proto_convert.h"

#include <chrono>
#include <cmath>

namespace dispatch::server {

void StopToProto(engine::PointId id, const engine::WarehouseMap& map, pb::ResolvedStop* out) {
  out->set_point_id(id);
  if (id < 0 || static_cast<std::size_t>(id) >= map.point_count()) return;
  const auto& p = map.point(id);
  out->set_point_name(p.name);
  out->mutable_position()->set_x(p.position.x());
  out->mutable_position()->set_y(p.position.y());
}

pb::WaypointAction ActionToProto(engine::WaypointAction a) {
  switch (a) {
    case engine::WaypointAction::kMove: return pb::WAYPOINT_ACTION_MOVE;
    case engine::WaypointAction::kPick: return pb::WAYPOINT_ACTION_PICK;
    case engine::WaypointAction::kDrop: return pb::WAYPOINT_ACTION_DROP;
    case engine::WaypointAction::kWait: return pb::WAYPOINT_ACTION_WAIT;
    case engine::WaypointAction::kPark: return pb::WAYPOINT_ACTION_PARK;
    case engine::WaypointAction::kCharge: return pb::WAYPOINT_ACTION_CHARGE;
  }
  return pb::WAYPOINT_ACTION_UNSPECIFIED;
}

pb::MotionMode MotionModeToProto(engine::MotionMode m) {
  switch (m) {
    case engine::MotionMode::kForward: return pb::MOTION_MODE_FORWARD;
    case engine::MotionMode::kReverse: return pb::MOTION_MODE_REVERSE;
    case engine::MotionMode::kCrabLeft: return pb::MOTION_MODE_CRAB_LEFT;
    case engine::MotionMode::kCrabRight: return pb::MOTION_MODE_CRAB_RIGHT;
    case engine::MotionMode::kSpinLeft: return pb::MOTION_MODE_SPIN_LEFT;
    case engine::MotionMode::kSpinRight: return pb::MOTION_MODE_SPIN_RIGHT;
    case engine::MotionMode::kArcForwardLeft: return pb::MOTION_MODE_ARC_FORWARD_LEFT;
    case engine::MotionMode::kArcForwardRight: return pb::MOTION_MODE_ARC_FORWARD_RIGHT;
    case engine::MotionMode::kArcReverseLeft: return pb::MOTION_MODE_ARC_REVERSE_LEFT;
    case engine::MotionMode::kArcReverseRight: return pb::MOTION_MODE_ARC_REVERSE_RIGHT;
  }
  return pb::MOTION_MODE_UNSPECIFIED;
}

namespace {

engine::Result<engine::StopSpec> StopFromProto(const pb::StopSpec& stop, const std::string& what) {
  switch (stop.target_case()) {
    case pb::StopSpec::kPointName:
      return engine::StopSpec(stop.point_name());
    case pb::StopSpec::kPosition:
      return engine::StopSpec(Eigen::Vector2d(stop.position().x(), stop.position().y()));
    case pb::StopSpec::TARGET_NOT_SET: break;
  }
  return engine::InvalidArgument(what + " has neither point_name nor position");
}

void BidToProto(const engine::Bid& b, const engine::WarehouseMap& map,
                const std::vector<std::string>& winners, pb::Bid* out) {
  out->set_robot_id(b.robot);
  out->set_reachable(b.reachable);
  out->set_queue_full(b.queue_full);
  out->set_priced(b.priced);
  out->set_travel_time(b.t_d);
  out->set_work_time(b.t_w);
  out->set_total_time(b.t_t);
  out->set_traffic_flow(b.flow);
  out->set_traffic_term(b.x);
  out->set_total(b.bid);
  out->set_ready_time(b.ready_time);
  for (const auto& [zone, n] : b.peaks) {
    auto* p = out->add_zone_peaks();
    p->set_zone_id(zone);
    if (zone >= 0 && static_cast<std::size_t>(zone) < map.zones().size()) {
      p->set_zone_name(map.zones()[static_cast<std::size_t>(zone)].name);
    }
    p->set_peak_robots(n);
  }
  out->set_winner(std::find(winners.begin(), winners.end(), b.robot) != winners.end());
}

void WaypointToProto(const OutboundWaypoint& w, pb::TimedWaypoint* out) {
  out->set_sequence(static_cast<std::uint64_t>(w.waypoint.seq));
  out->set_point_id(w.waypoint.point);
  out->set_x(w.waypoint.xy.x());
  out->set_y(w.waypoint.xy.y());
  out->set_eta(w.waypoint.eta);
  out->set_action(ActionToProto(w.waypoint.action));
  out->set_dwell(w.waypoint.dwell);
  out->set_released(w.released);
  out->set_order_id(w.order_id);
  if (w.waypoint.heading) out->set_heading(*w.waypoint.heading);
  if (w.waypoint.mode) out->set_motion_mode(MotionModeToProto(*w.waypoint.mode));
}

pb::PointKind KindToProto(engine::PointKind k) {
  switch (k) {
    case engine::PointKind::kLane: return pb::POINT_KIND_LANE;
    case engine::PointKind::kIntersection: return pb::POINT_KIND_INTERSECTION;
    case engine::PointKind::kPick: return pb::POINT_KIND_PICK;
    case engine::PointKind::kDrop: return pb::POINT_KIND_DROP;
    case engine::PointKind::kPark: return pb::POINT_KIND_PARK;
    case engine::PointKind::kCharge: return pb::POINT_KIND_CHARGE;
  }
  return pb::POINT_KIND_UNSPECIFIED;
}

std::optional<engine::RobotState> RobotStateFromProto(pb::RobotState s) {
  switch (s) {
    case pb::ROBOT_STATE_IDLE: return engine::RobotState::kIdle;
    case pb::ROBOT_STATE_MOVING: return engine::RobotState::kMoving;
    case pb::ROBOT_STATE_WORKING: return engine::RobotState::kWorking;
    case pb::ROBOT_STATE_WAITING: return engine::RobotState::kWaiting;
    case pb::ROBOT_STATE_PARKED: return engine::RobotState::kParked;
    case pb::ROBOT_STATE_CHARGING: return engine::RobotState::kCharging;
    case pb::ROBOT_STATE_FAULT: return engine::RobotState::kFault;
    case pb::ROBOT_STATE_OFFLINE: return engine::RobotState::kOffline;
    default: return std::nullopt;
  }
}

engine::Pose PoseFromProto(const pb::Pose& p) {
  engine::Pose pose;
  pose.position = Eigen::Vector2d(p.x(), p.y());
  pose.heading = p.theta();
  return pose;
}

}  // namespace

engine::Result<engine::OrderRequest> OrderRequestFromProto(const pb::SubmitOrderRequest& r) {
  engine::OrderRequest out;
  out.client_id = r.client_order_id();
  out.priority = r.priority();
  for (int i = 0; i < r.picks_size(); ++i) {
    auto stop = StopFromProto(r.picks(i), "pick " + std::to_string(i + 1));
    if (!stop.ok()) return stop.error();
    out.picks.push_back(*stop);
    if (r.picks(i).has_heading()) out.stop_headings[static_cast<std::size_t>(i)] = r.picks(i).heading();
  }
  if (!r.has_drop()) return engine::InvalidArgument("drop is required");
  auto drop = StopFromProto(r.drop(), "drop");
  if (!drop.ok()) return drop.error();
  out.drop = *drop;
  if (r.drop().has_heading()) out.stop_headings[out.picks.size()] = r.drop().heading();
  out.formation = r.formation();
  if (r.has_work_time()) out.work_time = r.work_time();
  if (r.has_release_time()) {
    if (!std::isfinite(r.release_time())) return engine::InvalidArgument("release_time must be finite");
    out.release_time = r.release_time();
  }
  return out;
}

std::optional<engine::OrderState> OrderStateFromProto(pb::OrderState s) {
  switch (s) {
    case pb::ORDER_STATE_ACCEPTED: return engine::OrderState::kAccepted;
    case pb::ORDER_STATE_ASSIGNED: return engine::OrderState::kAssigned;
    case pb::ORDER_STATE_IN_PROGRESS: return engine::OrderState::kInProgress;
    case pb::ORDER_STATE_COMPLETED: return engine::OrderState::kCompleted;
    case pb::ORDER_STATE_CANCELLED: return engine::OrderState::kCancelled;
    case pb::ORDER_STATE_FAILED: return engine::OrderState::kFailed;
    default: return std::nullopt;
  }
}

pb::OrderState OrderStateToProto(engine::OrderState s) {
  switch (s) {
    case engine::OrderState::kAccepted: return pb::ORDER_STATE_ACCEPTED;
    case engine::OrderState::kAssigned: return pb::ORDER_STATE_ASSIGNED;
    case engine::OrderState::kInProgress: return pb::ORDER_STATE_IN_PROGRESS;
    case engine::OrderState::kCompleted: return pb::ORDER_STATE_COMPLETED;
    case engine::OrderState::kCancelled: return pb::ORDER_STATE_CANCELLED;
    case engine::OrderState::kFailed: return pb::ORDER_STATE_FAILED;
  }
  return pb::ORDER_STATE_UNSPECIFIED;
}

engine::Result<RobotInbound> RobotInboundFromProto(const pb::RobotMessage& m) {
  RobotInbound in;
  switch (m.body_case()) {
    case pb::RobotMessage::kHello: {
      const auto& h = m.hello();
      in.kind = RobotInbound::Kind::kHello;
      in.robot_id = h.robot_id();
      in.robot_kind = h.kind() == pb::ROBOT_KIND_FOUR_WHEEL_STEER ? "four_wheel_steer" : "differential";
      in.pose = PoseFromProto(h.pose());
      in.last_acked_sequence = h.last_acked_sequence();
      in.diameter = h.diameter();
      in.max_speed = h.max_speed();
      if (!std::isfinite(in.diameter) || in.diameter < 0 || !std::isfinite(in.max_speed) || in.max_speed < 0) {
        return engine::InvalidArgument("hello: diameter and max_speed must be finite and >= 0");
      }
      // Sequences are stored as SQLite integers (< 2^63); no server sends 2^62 messages.
      if (in.last_acked_sequence > (std::uint64_t{1} << 62)) {
        return engine::InvalidArgument("hello: last_acked_sequence " + std::to_string(in.last_acked_sequence) +
                                       " is beyond 2^62; no server has sent that many messages");
      }
      return in;
    }
    case pb::RobotMessage::kStateReport: {
      const auto& s = m.state_report();
      in.kind = RobotInbound::Kind::kState;
      in.pose = PoseFromProto(s.pose());
      if (s.has_arc_id()) in.arc_id = s.arc_id();
      in.arc_offset = s.arc_offset();
      in.speed = s.speed();
      in.state = RobotStateFromProto(s.state());
      if (s.has_battery()) in.battery = s.battery();
      in.sequence = s.last_waypoint_sequence();
      in.message = s.message();
      return in;
    }
    case pb::RobotMessage::kWaypointReached:
      in.kind = RobotInbound::Kind::kWaypointReached;
      in.sequence = m.waypoint_reached().sequence();
      in.pose = PoseFromProto(m.waypoint_reached().pose());
      in.has_pose = m.waypoint_reached().has_pose();
      return in;
    case pb::RobotMessage::kTaskEvent: {
      const auto& e = m.task_event();
      if (e.type() != pb::TASK_EVENT_TYPE_PICKED && e.type() != pb::TASK_EVENT_TYPE_DROPPED) {
        return engine::InvalidArgument("task_event: type must be PICKED or DROPPED");
      }
      in.kind = RobotInbound::Kind::kTaskEvent;
      in.order_id = e.order_id();
      in.dropped = e.type() == pb::TASK_EVENT_TYPE_DROPPED;
      in.point_id = e.point_id();
      in.sequence = e.waypoint_sequence();
      return in;
    }
    case pb::RobotMessage::kHeartbeat:
      in.kind = RobotInbound::Kind::kHeartbeat;
      return in;
    case pb::RobotMessage::kAck:
      in.kind = RobotInbound::Kind::kAck;
      in.sequence = m.ack().sequence();
      return in;
    case pb::RobotMessage::BODY_NOT_SET: break;
  }
  return engine::InvalidArgument("robot message without a body");
}

void OrderToProto(const OrderView& view, const engine::WarehouseMap& map, pb::Order* out) {
  const engine::Order& o = view.record.order;
  out->set_id(o.id);
  out->set_client_order_id(o.client_id);
  out->set_priority(o.priority);
  for (engine::PointId p : o.picks) StopToProto(p, map, out->add_picks());
  StopToProto(o.drop, map, out->mutable_drop());
  for (const auto& [k, heading] : o.stop_headings) {
    if (k < o.picks.size()) out->mutable_picks(static_cast<int>(k))->set_heading(heading);
    if (k == o.picks.size()) out->mutable_drop()->set_heading(heading);
  }
  out->set_formation(o.formation);
  out->set_work_time(o.work_time);
  out->set_created_time(o.created_time);
  if (o.release_time) out->set_release_time(*o.release_time);
  out->set_state(OrderStateToProto(o.state));
  for (const auto& r : view.record.robots) out->add_robot_ids(r);
  if (view.finished_time) out->set_finished_time(*view.finished_time);
  out->set_distance(view.record.distance);
  out->set_reason(view.record.reason);
}

void EventToProto(const storage::OrderEvent& e, pb::OrderEvent* out) {
  out->set_event_id(static_cast<std::uint64_t>(e.id));
  out->set_order_id(e.order_id);
  switch (e.type) {
    case storage::OrderEventType::kCreated: out->set_type(pb::ORDER_EVENT_TYPE_CREATED); break;
    case storage::OrderEventType::kStateChanged: out->set_type(pb::ORDER_EVENT_TYPE_STATE_CHANGED); break;
    case storage::OrderEventType::kProgress: out->set_type(pb::ORDER_EVENT_TYPE_PROGRESS); break;
  }
  out->set_state(OrderStateToProto(e.state));
  if (e.previous_state) out->set_previous_state(OrderStateToProto(*e.previous_state));
  out->set_time(e.time);
  for (const auto& r : e.robots) out->add_robot_ids(r);
  out->set_detail(e.detail);
  out->set_actor(e.actor);
}

void AllocationToProto(const AllocationRecord& a, const engine::WarehouseMap& map,
                       pb::AllocationExplanation* out) {
  out->set_order_id(a.award.order_id);
  out->set_strategy(a.award.strategy);
  out->set_alpha(a.alpha);
  out->set_beta(a.beta);
  out->set_zeta(a.zeta);
  for (const auto& b : a.award.bids) BidToProto(b, map, a.award.winners, out->add_bids());
  for (const auto& b : a.award.companion_bids) BidToProto(b, map, a.award.winners, out->add_companion_bids());
  out->set_bids_total(static_cast<std::uint32_t>(a.bids_total));
  out->set_companion_bids_total(static_cast<std::uint32_t>(a.companion_bids_total));
  for (const auto& w : a.award.winners) out->add_winner_ids(w);
  out->set_reason(a.award.reason);
  out->set_time(a.time);
}

void OutboundToProto(const RobotOutbound& m, pb::ServerMessage* out) {
  out->set_sequence(m.sequence);
  out->set_server_time(m.server_time);
  switch (m.kind) {
    case RobotOutbound::Kind::kWelcome: {
      auto* w = out->mutable_welcome();
      w->set_time_scale(m.time_scale);
      w->set_server_time(m.server_time);
      w->set_server_unix_ms(std::chrono::duration_cast<std::chrono::milliseconds>(
                                std::chrono::system_clock::now().time_since_epoch())
                                .count());
      w->set_heartbeat_interval(m.heartbeat_interval);
      w->set_heartbeat_timeout(m.heartbeat_timeout);
      w->set_resume_from_sequence(m.resume_from_sequence);
      w->set_map_version(m.map_version);
      break;
    }
    case RobotOutbound::Kind::kAssignment: {
      auto* a = out->mutable_assignment();
      a->set_plan_id(m.plan_id);
      for (const auto& id : m.order_ids) a->add_order_ids(id);
      for (const auto& w : m.waypoints) WaypointToProto(w, a->add_waypoints());
      a->set_released_up_to_sequence(m.released_up_to);
      for (const auto& r : m.formation_members) a->add_formation_members(r);
      break;
    }
    case RobotOutbound::Kind::kPlanUpdate: {
      auto* u = out->mutable_plan_update();
      u->set_plan_id(m.plan_id);
      u->set_from_sequence(m.from_sequence);
      for (const auto& w : m.waypoints) WaypointToProto(w, u->add_waypoints());
      for (const auto& id : m.order_ids) u->add_order_ids(id);
      u->set_released_up_to_sequence(m.released_up_to);
      break;
    }
    case RobotOutbound::Kind::kCancel: {
      auto* c = out->mutable_cancel();
      for (const auto& id : m.order_ids) c->add_order_ids(id);
      c->set_reason(m.reason);
      break;
    }
    case RobotOutbound::Kind::kGrant: {
      auto* g = out->mutable_grant();
      g->set_intersection_id(m.intersection_id);
      g->set_intersection_name(m.intersection_name);
      g->set_release_up_to_sequence(m.released_up_to);
      break;
    }
    case RobotOutbound::Kind::kHold: {
      auto* h = out->mutable_hold();
      h->set_stop_at_sequence(m.stop_at_sequence);
      h->set_reason(m.reason);
      break;
    }
    case RobotOutbound::Kind::kResume:
      out->mutable_resume()->set_release_up_to_sequence(m.released_up_to);
      break;
  }
}

void MapToProto(const engine::WarehouseMap& map, const std::string& version, pb::GetMapResponse* out) {
  out->set_version(version);
  auto* m = out->mutable_map();
  m->set_name(map.name());
  m->mutable_floor_min()->set_x(map.floor_min().x());
  m->mutable_floor_min()->set_y(map.floor_min().y());
  m->mutable_floor_max()->set_x(map.floor_max().x());
  m->mutable_floor_max()->set_y(map.floor_max().y());
  for (std::size_t i = 0; i < map.points().size(); ++i) {
    const auto& p = map.points()[i];
    auto* q = m->add_points();
    q->set_id(static_cast<int>(i));
    q->set_name(p.name);
    q->mutable_position()->set_x(p.position.x());
    q->mutable_position()->set_y(p.position.y());
    q->set_kind(KindToProto(p.kind));
    q->set_zone_id(p.zone);
  }
  for (std::size_t i = 0; i < map.arcs().size(); ++i) {
    const auto& a = map.arcs()[i];
    auto* q = m->add_arcs();
    q->set_id(static_cast<int>(i));
    q->set_from_point(a.from);
    q->set_to_point(a.to);
    q->set_length(a.length);
    q->set_max_speed(a.max_speed);
    if (a.reverse_arc >= 0) q->set_reverse_arc(a.reverse_arc);
  }
  for (std::size_t i = 0; i < map.zones().size(); ++i) {
    const auto& z = map.zones()[i];
    auto* q = m->add_zones();
    q->set_id(static_cast<int>(i));
    q->set_name(z.name);
    for (const auto& v : z.polygon) {
      auto* p = q->add_polygon();
      p->set_x(v.x());
      p->set_y(v.y());
    }
    q->set_area(z.area);
  }
  for (std::size_t i = 0; i < map.intersections().size(); ++i) {
    const auto& x = map.intersections()[i];
    auto* q = m->add_intersections();
    q->set_id(static_cast<int>(i));
    q->set_name(x.name);
    for (auto p : x.inner) q->add_inner_points(p);
    for (auto p : x.approach) q->add_approach_points(p);
  }
  for (const auto& s : map.stations()) {
    auto* q = m->add_stations();
    q->set_name(s.name);
    q->set_point_id(s.point);
    q->set_capacity(s.capacity);
  }
  for (const auto& s : map.shelves()) {
    auto* q = m->add_shelves();
    q->set_name(s.name);
    q->mutable_min()->set_x(s.min.x());
    q->mutable_min()->set_y(s.min.y());
    q->mutable_max()->set_x(s.max.x());
    q->mutable_max()->set_y(s.max.y());
  }
  for (const auto& f : map.free_spaces()) {
    auto* q = m->add_free_spaces();
    q->set_name(f.name);
    for (const auto& v : f.polygon) {
      auto* p = q->add_polygon();
      p->set_x(v.x());
      p->set_y(v.y());
    }
    q->set_area(f.area);
    for (auto p : f.points) q->add_point_ids(p);
  }
}

}  // namespace dispatch::server
