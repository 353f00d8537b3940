// TrafficGate: a formation team leaving its drop point, its members back on the controller's
// floor one at a time (the teams' other phases are in traffic_gate_teams.cpp).
#include <algorithm>
#include <string>
#include <vector>

#include "engine/fleet/formation.h"
#include "engine/traffic/traffic_gate_impl.h"

namespace dispatch::engine {

// After the drop the members go back into the controller one at a time while the team agent
// still holds the drop point D (and so every point near it): a member with work ahead is placed
// at the first point of its onward route, an idle one at a free neighbour of D; the last one
// takes D itself from the team agent. True when every member is back.
bool GateImpl::StepLeaving(GateTeam& team, double t, std::vector<GateEffect>& out) {
  const int group = GroupOf(team.order);
  const bool agent_on_floor = TeamAgentOnFloor(team);

  const PointId d = team.drop;
  std::vector<GateBot*> pending;
  for (const std::string& id : team.members) {
    auto b = bots.find(id);
    if (b != bots.end() && b->second.team == team.order) pending.push_back(&b->second);
  }
  // Members with somewhere to go leave first (an idle one may stay on D).
  auto onward = [&](const GateBot& b) -> long {
    for (long j = std::max(0L, b.idx + 1); j < static_cast<long>(b.plan.waypoints.size()); ++j) {
      if (b.plan.waypoints[static_cast<std::size_t>(j)].point != d) return j;
    }
    return -1;
  };
  std::stable_sort(pending.begin(), pending.end(),
                   [&](const GateBot* a, const GateBot* b) { return (onward(*a) >= 0) > (onward(*b) >= 0); });
  auto back = [&](GateBot& b) {
    // Until it has left the formation's envelope it still stands in its slot, D_f off the point.
    ctl.SetEnvelope(static_cast<std::size_t>(b.ctl), FormationRadius());
    b.team.clear();
    BecomeFormer(b, team.order, d);
    b.leg_stale = true;
    b.left = false;
  };
  auto place = [&](GateBot& b, PointId at) {
    if (b.ctl >= 0) ctl.SetGroup(static_cast<std::size_t>(b.ctl), group);
    if (b.ctl < 0) {
      auto added = ctl.AddRobot(b.id, at, group);
      if (!added.ok()) return false;
      b.ctl = static_cast<int>(*added);
      ctl.SetRank(*added, b.plan.release);
      return true;
    }
    if (!ctl.removed(static_cast<std::size_t>(b.ctl))) ctl.Remove(static_cast<std::size_t>(b.ctl));
    return ctl.Place(static_cast<std::size_t>(b.ctl), at).ok();
  };
  for (std::size_t k = 0; k < pending.size(); ++k) {
    GateBot& b = *pending[k];
    if (d == kNoPoint) {  // no agent to leave from (e.g. after a restart): where it stands
      if (!PlaceNear(b)) continue;  // retried next step
      back(b);
      notes.push_back("formation " + team.order + ": " + b.id + " placed near where it stands");
      continue;
    }
    const bool last = k + 1 == pending.size();
    if (last) {
      // The team agent keeps D (and its envelope over the slots) until the others have
      // driven to the points they were placed at.
      const double envelope = config.point_clearance + FormationRadius();
      for (const std::string& id : team.members) {
        const GateBot& o = bots.at(id);
        if (&o == &b || !o.team.empty()) continue;
        const bool out = o.reached_seq >= o.leave_seq ||
                         (o.has_xy && (o.xy - map->point(d).position).norm() >= envelope);
        if (!out) return false;
      }
      if (agent_on_floor) ctl.Remove(static_cast<std::size_t>(team.ctl));
      if (!place(b, d)) {
        if (agent_on_floor) (void)ctl.Place(static_cast<std::size_t>(team.ctl), d);
        return false;
      }
      if (team.ctl >= 0) team_pool.push_back(static_cast<std::size_t>(team.ctl));
      team.ctl = -1;
      back(b);
      notes.push_back("formation " + team.order + ": " + b.id + " takes '" + map->point(d).name +
                      "' over, the team is done");
      return true;
    }
    const long j = onward(b);
    // Where it goes: its onward route's first point, or (idle) any free neighbour of D that is
    // no service point and outside intersections.
    std::vector<PointId> targets;
    if (j >= 0) {
      targets.push_back(b.plan.waypoints[static_cast<std::size_t>(j)].point);
    } else {
      for (ArcId a : map->out_arcs(d)) {
        const PointId q = map->arc(a).to;
        if (!IsServicePoint(map->point(q).kind) && map->IntersectionOf(q) < 0) targets.push_back(q);
      }
    }
    // An idle member of a broken-up team drives on home (its parking point) from there: left
    // on the neighbour it would close the way off for the next member (a team broken up inside
    // an intersection has few ways off that are no intersection points).
    auto home_route = [&](PointId q) {
      std::vector<PointId> route{d, q};
      if (!team.broken || j >= 0 || b.home == kNoPoint || b.home == q) return route;
      auto path = routes->Path(q, b.home);
      if (path.ok()) route.insert(route.end(), path->points.begin() + 1, path->points.end());
      return route;
    };
    PointId target = kNoPoint;
    for (PointId q : targets) {
      if (place(b, q)) {
        target = q;
        break;
      }
    }
    if (target == kNoPoint) {  // retried next step; the team agent waits on whoever is in the way
      if (agent_on_floor && !targets.empty()) {
        const auto tr = static_cast<std::size_t>(team.ctl);
        const int blocker = ctl.BlockerOf(targets.front(), tr, 0.0);
        ctl.WaitOn(tr, blocker, t,
                   blocker >= 0 ? "formation " + team.order + ": " + b.id + " leaves for '" +
                                      map->point(targets.front()).name + "', held by " +
                                      ctl.robot_id(static_cast<std::size_t>(blocker))
                                : std::string());
      }
      return false;
    }
    if (agent_on_floor) ctl.WaitOn(static_cast<std::size_t>(team.ctl), -1, t, {});
    notes.push_back("formation " + team.order + ": " + b.id + " leaves '" + map->point(d).name + "' for '" +
                    map->point(target).name + "' (onward waypoint " + std::to_string(j) + ")");
    long first_new = j;
    if (j < 0) {  // idle: a move to the neighbour (and home, see home_route)
      // Its first new waypoint is the move to the neighbour, not the last one: with the way
      // home appended, every waypoint up to home was taken as passed (reached, released) and
      // the robot drove home unguarded (found by the safety check: 0.019 m, a member of a
      // broken-up team driving through a robot on its way home).
      first_new = static_cast<long>(b.plan.waypoints.size());
      RewriteLeg(b, first_new - 1, home_route(target), -1, t, out);
    }
    b.leave_seq = static_cast<std::uint64_t>(b.plan.waypoints[static_cast<std::size_t>(first_new)].seq);
    if (first_new - 1 > b.idx) {  // the waypoints still at D are passed on the way out
      b.idx = first_new - 1;
      b.reached_seq = std::max<std::uint64_t>(b.reached_seq, b.plan.waypoints[static_cast<std::size_t>(b.idx)].seq);
    }
    back(b);
  }
  if (d == kNoPoint) {  // done once every member is back on the floor
    for (const GateBot* b : pending) {
      if (!b->team.empty()) return false;
    }
    if (agent_on_floor) ctl.Remove(static_cast<std::size_t>(team.ctl));
    if (team.ctl >= 0) team_pool.push_back(static_cast<std::size_t>(team.ctl));
    team.ctl = -1;
    return true;
  }
  return pending.empty();
}

}  // namespace dispatch::engine
