#include "server/snapshot_builder.h"

#include <cmath>
#include <utility>

namespace dispatch::server {
namespace {

// Live zone densities from the connected robots' reported positions (their current point's
// zone, else the zone around their pose).
std::vector<ZoneView> ZoneViews(const engine::WarehouseMap& map, const std::map<std::string, RobotView>& robots) {
  const auto& zones = map.zones();
  std::vector<ZoneView> out(zones.size());
  for (const auto& [id, view] : robots) {
    if (!view.connected) continue;
    const engine::Robot& r = view.robot;
    long zone = -1;
    if (r.current_point != engine::kNoPoint) {
      zone = map.point(r.current_point).zone;
    } else {
      for (std::size_t z = 0; z < zones.size() && zone < 0; ++z) {
        if (zones[z].Contains(r.pose.position)) zone = static_cast<long>(z);
      }
    }
    if (zone >= 0) out[static_cast<std::size_t>(zone)].robots.push_back(id);
  }
  for (std::size_t z = 0; z < zones.size(); ++z) {
    if (zones[z].area > 0) out[z].density = static_cast<double>(out[z].robots.size()) / zones[z].area;
  }
  return out;
}

}  // namespace

std::shared_ptr<Snapshot> BuildSnapshot(const engine::WarehouseMap& map, const engine::JournaledCore& core,
                                        const RobotSessions& sessions, OrderViews& book, const SnapshotFacts& facts) {
  auto snap = std::make_shared<Snapshot>();
  snap->version = facts.version;
  snap->time = facts.time;
  snap->map_name = map.name();
  snap->map_version = facts.map_version;
  snap->strategy = facts.strategy;
  snap->time_scale = facts.time_scale;
  snap->orders = book.all();
  snap->finished_in_store = book.finished_in_store();
  snap->index = book.Index();
  const engine::TrafficGate* gate = core.gate();
  for (const auto& [id, r] : core.robots()) {
    RobotView view;
    view.robot = r.robot;
    if (const RobotSession* s = sessions.Find(id)) {
      view.kind = s->kind;
      view.connected = s->link != nullptr;
      view.last_seen = s->last_seen;
    }
    view.marks = r.marks;
    view.sent_to = core.TripTo(id);
    if (r.has_assignment) {
      view.plan_id = r.assignment.plan_id;
      view.waypoints = r.assignment.plan.waypoints.size();
    }
    if (gate) {
      engine::GateRobotState traffic = gate->RobotState(id);
      view.held = traffic.held;
      view.hold_reason = std::move(traffic.reason);
      view.formation = std::move(traffic.formation);
    }
    snap->robots.emplace(id, std::move(view));
  }
  snap->zones = ZoneViews(map, snap->robots);
  snap->traffic.implausible_reports = facts.implausible_reports;
  if (!gate) return snap;
  for (auto& g : gate->Intersections()) snap->intersections.push_back({std::move(g.holders), std::move(g.waiting)});
  TrafficView& t = snap->traffic;
  const engine::CoreCounts& counts = core.counts();
  t.enabled = true;
  t.grants = counts.grants;
  t.holds = counts.holds;
  t.replans = counts.replans;
  t.deadlocks_resolved = gate->stats().deadlocks_resolved;
  t.head_on_conflicts = gate->stats().head_on_conflicts;
  t.nudges = gate->stats().nudges;
  if (facts.awaiting_reconnect) t.awaiting_reconnect.assign(facts.awaiting_reconnect->begin(), facts.awaiting_reconnect->end());
  const engine::MinDistance& d = facts.min_distance;
  if (std::isfinite(d.distance)) {
    t.min_distance = d.distance;
    t.min_pair_a = d.a;
    t.min_pair_b = d.b;
    t.min_time = d.time;
  }
  return snap;
}

}  // namespace dispatch::server
