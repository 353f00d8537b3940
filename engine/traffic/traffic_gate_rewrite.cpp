// TrafficGate: a robot's plan rewritten - a leg's new route spliced into its waypoints (a
// detour, a back-off, a nudge, leaving a team, driving back to a rendezvous), a formation
// member's slot turning in place about the centre where the heading changes - and the plan's
// index rebuilt after any change (Reindex). The shared state is in traffic_gate_impl.h.
#include <algorithm>
#include <cmath>
#include <iterator>
#include <string>
#include <vector>

#include "engine/fleet/formation.h"
#include "engine/traffic/traffic_gate_impl.h"

namespace dispatch::engine {

// Rewrites b's waypoints after index `cut` (-1: a new anchor too) with moves along `route`
// (route[0] = the point it stands at), then continues with the old waypoints from `resume`
// on (re-sequenced and re-timed; -1: none); returns the new index of `resume` (or -1). When
// the old waypoint at `resume` is at the route's last point it stands for that point (a stop
// keeps its action and dwell). A formation member (`member` >= 0) turns in place about the
// centre before each segment with a new heading, and at the route's end to the heading of the
// waypoint it resumes at, in steps of at most FormationOptions::max_rotation_step, each as long
// as its slot's arc takes at speed v: the three members' moves stay as long as each other's,
// so they keep their triangle (members driven straight from one heading's slot to the next
// drove legs of different lengths, and the triangle's sides ranged over 0.21-0.53 m).
long GateImpl::RewriteLeg(GateBot& b, long cut, const std::vector<PointId>& route, long resume, double t,
                          std::vector<GateEffect>& out, int member) {
  double clock = std::max(t, cut >= 0 ? Departure(b, cut) : t);
  // The plan is rebuilt from its old self, taken out (not copied).
  const std::vector<Waypoint> old = std::move(b.plan.waypoints);
  std::vector<std::string> old_orders = std::move(b.plan.order_of);
  std::vector<Waypoint> w(old.begin(), old.begin() + (cut + 1));
  std::vector<std::string> ow(std::make_move_iterator(old_orders.begin()),
                              std::make_move_iterator(old_orders.begin() + (cut + 1)));
  w.reserve(old.size() + route.size());
  ow.reserve(old.size() + route.size());
  const std::uint64_t from = cut + 1 < static_cast<long>(old.size())
                                 ? static_cast<std::uint64_t>(old[static_cast<std::size_t>(cut + 1)].seq)
                                 : b.plan.next_sequence;
  const std::string order = resume >= 0 ? old_orders[static_cast<std::size_t>(resume)] : std::string();
  const bool team = member >= 0 && cut >= 0;
  const double speed = std::max(1e-6, config.speed);
  // A formation's heading: as its slot at the cut says, then each segment's.
  double heading = 0.0;
  if (team) {
    const Waypoint& c = old[static_cast<std::size_t>(cut)];
    heading = FormationHeadingOfSlot(c.xy - map->point(c.point).position, member);
  }
  auto move = [&](PointId p) {
    Waypoint m;
    m.seq = static_cast<int>(b.plan.next_sequence++);
    m.point = p;
    m.xy = map->point(p).position;
    if (team) m.xy += FormationOffsets(heading)[static_cast<std::size_t>(member)];
    m.eta = clock;
    m.action = WaypointAction::kMove;
    w.push_back(m);
    ow.push_back(w.size() == 1 ? std::string() : order);
  };
  auto turn = [&](PointId p, double to) {  // in place about the centre at p
    const double delta = WrapAngle(to - heading);
    if (!team || std::abs(delta) <= 1e-6) return;  // the same for every member (heading noise)
    const FormationTurn rotation = PlanFormationTurn(delta, speed);
    const double start = heading;
    for (int s = 1; s <= rotation.steps; ++s) {
      clock += rotation.step_time;
      heading = start + delta * s / rotation.steps;
      move(p);
    }
    heading = to;
  };
  if (cut < 0) move(route.front());  // the anchor: where it stands
  Eigen::Vector2d at = map->point(route.front()).position;
  for (std::size_t k = 1; k < route.size(); ++k) {
    const Eigen::Vector2d xy = map->point(route[k]).position;
    if ((xy - at).norm() > 1e-9) turn(route[k - 1], std::atan2(xy.y() - at.y(), xy.x() - at.x()));
    clock += (xy - at).norm() / speed;
    at = xy;
    if (k + 1 == route.size() && resume >= 0 && old[static_cast<std::size_t>(resume)].point == route[k]) {
      const Waypoint& r = old[static_cast<std::size_t>(resume)];
      const double resumed_heading = team ? FormationHeadingOfSlot(r.xy - map->point(r.point).position, member) : heading;
      if (!team || std::abs(WrapAngle(resumed_heading - heading)) <= 1e-6) break;
      move(route[k]);  // arrive, then turn to the heading the plan resumes with
      turn(route[k], resumed_heading);
      break;
    }
    move(route[k]);
  }
  const long resumed = resume >= 0 ? static_cast<long>(w.size()) : -1;
  if (resume >= 0) {
    const double shift = std::max(0.0, clock - old[static_cast<std::size_t>(resume)].eta);
    for (long i = resume; i < static_cast<long>(old.size()); ++i) {
      Waypoint m = old[static_cast<std::size_t>(i)];
      m.seq = static_cast<int>(b.plan.next_sequence++);
      m.eta += shift;
      w.push_back(m);
      ow.push_back(std::move(old_orders[static_cast<std::size_t>(i)]));
    }
  }
  b.plan.waypoints = std::move(w);
  b.plan.order_of = std::move(ow);
  Reindex(b);
  GateEffect e;
  e.kind = GateEffect::Kind::kRewrite;
  e.robot = b.id;
  e.waypoints = b.plan.waypoints;
  e.from_sequence = from;
  out.push_back(std::move(e));
  return resumed;
}

void GateImpl::Reindex(GateBot& b) {
  ++b.plan_version;
  for (const Waypoint& w : b.plan.waypoints) {
    b.plan.next_sequence = std::max<std::uint64_t>(b.plan.next_sequence, w.seq + 1);
  }
  b.spans.clear();
  for (const auto& team : b.plan.teams) b.spans.emplace(team.first, FindSpan(b, team.first));
  b.idx = -1;
  for (long i = static_cast<long>(b.plan.waypoints.size()) - 1; i >= 0; --i) {
    if (static_cast<std::uint64_t>(b.plan.waypoints[static_cast<std::size_t>(i)].seq) <= b.reached_seq) {
      b.idx = i;
      break;
    }
  }
}

}  // namespace dispatch::engine
