#include "server/rest_views.h"

#include <google/protobuf/util/json_util.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>


#include "engine/common/text.h"
#include "formats/json_keys.h"
#include "server/proto_convert.h"

namespace dispatch::server {
namespace {

pb::RobotState RobotStateToProto(engine::RobotState s) {
  switch (s) {
    case engine::RobotState::kIdle: return pb::ROBOT_STATE_IDLE;
    case engine::RobotState::kMoving: return pb::ROBOT_STATE_MOVING;
    case engine::RobotState::kWorking: return pb::ROBOT_STATE_WORKING;
    case engine::RobotState::kWaiting: return pb::ROBOT_STATE_WAITING;
    case engine::RobotState::kParked: return pb::ROBOT_STATE_PARKED;
    case engine::RobotState::kCharging: return pb::ROBOT_STATE_CHARGING;
    case engine::RobotState::kFault: return pb::ROBOT_STATE_FAULT;
    case engine::RobotState::kOffline: return pb::ROBOT_STATE_OFFLINE;
  }
  return pb::ROBOT_STATE_UNSPECIFIED;
}

template <class Ids>
void AddAll(const Ids& ids, google::protobuf::RepeatedPtrField<std::string>* out) {
  for (const auto& id : ids) out->Add(std::string(id));
}

}  // namespace

std::string ValidUtf8(const std::string& text) {
  using nlohmann::json;
  return json::parse(json(text).dump(-1, ' ', false, json::error_handler_t::replace)).get<std::string>();
}

std::string ToJson(const google::protobuf::Message& message) {
  google::protobuf::util::JsonPrintOptions options;
  options.always_print_primitive_fields = true;
  options.preserve_proto_field_names = true;
  std::string out;
  if (auto status = google::protobuf::util::MessageToJsonString(message, &out, options); !status.ok()) {
    spdlog::error("REST: {} not written as JSON: {}", message.GetTypeName(), status.ToString());
    return ErrorJson("the answer could not be written as JSON: " + std::string(status.message()));
  }
  return out;
}

engine::Status FromJson(const std::string& body, google::protobuf::Message* out) {
  // Whether it is JSON at all first: protobuf's parser says less about that.
  nlohmann::json j;
  std::optional<std::string> key;
  try {
    j = formats::ParseNotingDuplicateKey(body, &key);
  } catch (const nlohmann::json::exception& e) {
    return engine::InvalidArgument("the body is not JSON: " + ValidUtf8(e.what()));
  }
  if (!j.is_object()) return engine::InvalidArgument("the body must be a JSON object (a " + out->GetTypeName() + ")");
  if (key) {
    return engine::InvalidArgument("the body names the key '" + engine::Clipped(ValidUtf8(*key)) + "' twice");
  }
  google::protobuf::util::JsonParseOptions options;
  options.ignore_unknown_fields = false;
  if (auto status = google::protobuf::util::JsonStringToMessage(body, out, options); !status.ok()) {
    return engine::InvalidArgument("the body is not a " + out->GetTypeName() + ": " +
                                   ValidUtf8(std::string(status.message())));
  }
  return engine::Ok{};
}

std::string ErrorJson(const std::string& message) {
  pb::ErrorReply reply;
  reply.set_error(ValidUtf8(message));
  std::string out;
  (void)google::protobuf::util::MessageToJsonString(reply, &out);
  return out;
}

void RobotToProto(const RobotView& view, const engine::WarehouseMap& map, pb::RobotInfo* out) {
  const engine::Robot& r = view.robot;
  out->set_id(r.id);
  out->set_state(RobotStateToProto(r.state));
  out->set_connected(view.connected);
  out->set_kind(view.kind == "four_wheel_steer" ? pb::ROBOT_KIND_FOUR_WHEEL_STEER : pb::ROBOT_KIND_DIFFERENTIAL);
  out->mutable_pose()->set_x(r.pose.position.x());
  out->mutable_pose()->set_y(r.pose.position.y());
  out->mutable_pose()->set_theta(r.pose.heading);
  out->set_diameter(r.diameter);
  out->set_max_speed(r.max_speed);
  AddAll(r.task_queue, out->mutable_order_ids());
  out->set_plan_id(view.plan_id);
  out->set_plan_waypoints(static_cast<std::uint32_t>(view.waypoints));
  out->set_last_seen_time(view.last_seen);
  if (r.battery) out->set_battery(*r.battery);
  out->set_formation_order_id(view.formation);
  out->set_held(view.held);
  out->set_hold_reason(view.hold_reason);
  out->set_paused_by(view.marks.paused_by);
  out->set_out_of_service_by(view.marks.out_of_service_by);
  out->set_off_floor(view.marks.off_floor);
  if (r.current_point != engine::kNoPoint) StopToProto(r.current_point, map, out->mutable_point());
  if (view.sent_to != engine::kNoPoint) StopToProto(view.sent_to, map, out->mutable_sent_to());
}

void StatusToProto(const Snapshot& snap, pb::ServiceState* out) {
  out->set_map_name(snap.map_name);
  out->set_map_version(snap.map_version);
  out->set_strategy(snap.strategy);
  out->set_time(snap.time);
  out->set_time_scale(snap.time_scale);
  out->set_snapshot(snap.version);
  pb::OrderCounts* counts = out->mutable_orders();
  auto count = [counts](engine::OrderState state, std::uint32_t n) {
    switch (state) {
      case engine::OrderState::kAccepted: counts->set_accepted(counts->accepted() + n); break;
      case engine::OrderState::kAssigned: counts->set_assigned(counts->assigned() + n); break;
      case engine::OrderState::kInProgress: counts->set_in_progress(counts->in_progress() + n); break;
      case engine::OrderState::kCompleted: counts->set_completed(counts->completed() + n); break;
      case engine::OrderState::kCancelled: counts->set_cancelled(counts->cancelled() + n); break;
      case engine::OrderState::kFailed: counts->set_failed(counts->failed() + n); break;
    }
  };
  for (const auto& o : snap.orders) count(o->record.order.state, 1);
  for (const auto& [state, n] : snap.finished_in_store) count(state, static_cast<std::uint32_t>(n));
  std::uint32_t connected = 0;
  for (const auto& [id, r] : snap.robots) connected += r.connected ? 1 : 0;
  out->mutable_robots()->set_total(static_cast<std::uint32_t>(snap.robots.size()));
  out->mutable_robots()->set_connected(connected);
  const TrafficView& t = snap.traffic;
  pb::TrafficStatus* traffic = out->mutable_traffic();
  traffic->set_control(t.enabled);
  traffic->set_grants(t.grants);
  traffic->set_holds(t.holds);
  traffic->set_replans(t.replans);
  traffic->set_deadlocks_resolved(t.deadlocks_resolved);
  traffic->set_head_on_conflicts(t.head_on_conflicts);
  traffic->set_nudges(t.nudges);
  traffic->set_implausible_reports(t.implausible_reports);
  AddAll(t.awaiting_reconnect, traffic->mutable_awaiting_reconnect());
  if (t.min_distance >= 0) {
    pb::RobotDistance* d = traffic->mutable_min_robot_distance();
    d->set_distance(t.min_distance);
    d->add_robot_ids(t.min_pair_a);
    d->add_robot_ids(t.min_pair_b);
    d->set_time(t.min_time);
  }
}

void RoutesToProto(const OrderRoutes& routes, pb::OrderDetail* out) {
  auto& by_robot = *out->mutable_routes();
  for (const auto& [robot, waypoints] : routes) {
    pb::OrderRoute& route = by_robot[robot];
    for (const RouteWaypoint& w : waypoints) {
      pb::RouteWaypoint* p = route.add_waypoints();
      p->set_sequence(w.seq);
      p->mutable_position()->set_x(w.xy.x());
      p->mutable_position()->set_y(w.xy.y());
      p->set_action(ActionToProto(w.action));
      p->set_released(w.released);
      if (w.heading) p->set_heading(*w.heading);
      if (w.mode) p->set_motion_mode(MotionModeToProto(*w.mode));
    }
  }
}

void ZonesToProto(const Snapshot& snap, const engine::WarehouseMap& map, pb::ZoneList* out) {
  out->set_time(snap.time);
  const auto& zones = map.zones();
  for (std::size_t z = 0; z < zones.size(); ++z) {
    pb::ZoneState* zone = out->add_zones();
    zone->set_id(zones[z].name);
    for (const auto& v : zones[z].polygon) {
      pb::Vec2* p = zone->add_polygon();
      p->set_x(v.x());
      p->set_y(v.y());
    }
    zone->set_area(zones[z].area);
    if (z < snap.zones.size()) {
      AddAll(snap.zones[z].robots, zone->mutable_robot_ids());
      zone->set_density(snap.zones[z].density);
    }
  }
}

void IntersectionsToProto(const Snapshot& snap, const engine::WarehouseMap& map, bool only_active,
                          pb::IntersectionList* out) {
  out->set_time(snap.time);
  out->set_control(snap.traffic.enabled);
  for (std::size_t i = 0; i < map.intersections().size(); ++i) {
    const auto& x = map.intersections()[i];
    const IntersectionView* live = i < snap.intersections.size() ? &snap.intersections[i] : nullptr;
    if (only_active && (!live || (live->holders.empty() && live->waiting.empty()))) continue;
    pb::IntersectionState* state = out->add_intersections();
    state->set_id(x.name);
    for (engine::PointId p : x.inner) state->add_inner(map.point(p).name);
    for (engine::PointId p : x.approach) state->add_approach(map.point(p).name);
    if (live) {
      AddAll(live->holders, state->mutable_holder_ids());
      AddAll(live->waiting, state->mutable_waiting_ids());
    }
  }
}

}  // namespace dispatch::server
