// TrafficGate's solo agents: placing robots on the floor, their legs (requests, adopted
// routes), reaching waypoints, and their team keys. Rewriting a plan is in
// traffic_gate_rewrite.cpp, formations in traffic_gate_teams.cpp, the public interface in
// traffic_gate.cpp, the shared state in traffic_gate_impl.h.
#include <algorithm>
#include <optional>
#include <cmath>
#include <limits>
#include <numbers>
#include <unordered_map>
#include <iterator>
#include <utility>

#include "engine/fleet/formation.h"
#include "engine/traffic/traffic_gate_impl.h"

namespace dispatch::engine {

// --- Solo agents --------------------------------------------------------------------------

bool GateImpl::OnFloor(const GateBot& b) const { return b.ctl >= 0 && !ctl.removed(static_cast<std::size_t>(b.ctl)); }

bool GateImpl::PlaceBot(GateBot& b, PointId at) {
  if (at == kNoPoint) return false;
  if (b.ctl < 0) {
    auto added = ctl.AddRobot(b.id, at);
    if (!added.ok()) return false;
    b.ctl = static_cast<int>(*added);
    ctl.SetRank(*added, b.plan.release);
  } else if (ctl.removed(static_cast<std::size_t>(b.ctl))) {
    if (!ctl.Place(static_cast<std::size_t>(b.ctl), at).ok()) return false;
  } else {
    return true;
  }
  b.leg_stale = true;
  b.left = false;
  return true;
}

// Re-places a bot that is not on the floor at the free point nearest to where it is: its
// plan's current waypoint (or the next) while that is the waypoint it last reached, else the
// point nearest its last reported pose. A plan cut back to its anchor (its orders taken away
// after kBlocked or a cancel) leaves idx at the anchor, where the plan started - e.g. its home
// - while the robot stands elsewhere (issue 15 §3b: never place a robot where it is not). A
// former member of a formation that is gone may stand in its slot, D_f off the point: it keeps
// the formation's envelope until its next arrival.
bool GateImpl::PlaceNear(GateBot& b) {
  std::vector<PointId> candidates;
  const long n = static_cast<long>(b.plan.waypoints.size());
  const bool current = !b.has_xy || b.idx < 0 ||
                       (b.idx < n && static_cast<std::uint64_t>(b.plan.waypoints[static_cast<std::size_t>(b.idx)].seq) ==
                                         b.reached_seq);
  if (current && b.idx >= 0 && b.idx < n) candidates.push_back(b.plan.waypoints[static_cast<std::size_t>(b.idx)].point);
  if (current && b.idx + 1 < n) candidates.push_back(b.plan.waypoints[static_cast<std::size_t>(b.idx + 1)].point);
  if (b.has_xy) candidates.push_back(map->NearestPoint(b.xy));
  if (b.ctl >= 0) SetGroups(b);  // teammates (a formation it is in or just left) do not keep it off
  for (PointId p : candidates) {
    if (!PlaceBot(b, p)) continue;
    if (!b.former_team.empty() && !teams.count(b.former_team)) {
      ctl.SetEnvelope(static_cast<std::size_t>(b.ctl), FormationRadius());
    }
    return true;
  }
  return false;
}

void GateImpl::PlaceStrays() {
  for (auto it = strays.begin(); it != strays.end();) {
    auto bot = bots.find(*it);
    // Off the floor and in no team, it stands where it stands (the controller keeps strangers
    // clear of it) until it is placed: while a team it was in still holds the point (its
    // former team, or one it was given next and never joined), it waits. Found by the
    // safety check: a stray given a formation that broke up before it joined was dropped from
    // the strays, and a robot drove up to it at 0.231 m.
    const bool stray = bot != bots.end() && bot->second.team.empty() && !OnFloor(bot->second);
    const bool wait = stray && !bot->second.former_team.empty() && teams.count(bot->second.former_team);
    if (stray && (wait || !PlaceNear(bot->second))) {
      ++it;
    } else {
      // Placed, or no longer a stray (placed elsewhere, in a team again).
      if (bot != bots.end() && bot->second.ctl >= 0) ctl.ClearStanding(static_cast<std::size_t>(bot->second.ctl));
      it = strays.erase(it);
    }
  }
}

// One solo agent standing or driving: releases, requests, rewrites.
void GateImpl::StepSolo(GateBot& b, double t, std::vector<GateEffect>& out) {
  if (!b.team.empty() || b.removed) return;
  if (b.connected && b.synced && !b.plan.teams.empty()) {
    if (auto inside = SpanAround(b)) {  // inside its formation's segment without the team
      if (RejoinTeam(b, inside->first, inside->second, t, out)) return;
    }
  }
  if (!OnFloor(b)) {
    if (!PlaceNear(b)) return;
  }
  const auto r = static_cast<std::size_t>(b.ctl);
  const auto& w = b.plan.waypoints;
  const long n = static_cast<long>(w.size());
  // On its way to a rendezvous, or leaving one, a member may come closer to its teammates.
  SetGroups(b);
  const PointId next = ctl.Next(r);
  if (next != kNoPoint) {  // driving: the point behind is released once clear of it
    // Clear of it by eps2 (Chu2024 eq. (11)): a formation may be given the point behind.
    if (!b.left && b.has_xy &&
        (b.xy - map->point(ctl.At(r)).position).norm() >= config.point_clearance + FormationRadius()) {
      ctl.LeftPoint(r);
      b.left = true;
      if (!b.former_team.empty() && !strays.empty()) PlaceStrays();  // a teammate's slot may be at the point it left
    }
    if (b.left && b.run_next == next && b.run_idx == b.idx && b.run_version == b.plan_version) return;
    Release(b, GrantedRunEnd(b, ctl.At(r), next), map->IntersectionOf(next), out);
    if (b.left) {  // released up to the run at next: the same again would change nothing
      b.run_next = next;
      b.run_idx = b.idx;
      b.run_version = b.plan_version;
    }
    return;
  }
  if (!b.connected || !b.synced) return;
  const PointId at = ctl.At(r);
  // The run of waypoints at the point it stands on: released at once (no move needed).
  std::string join_order;
  const long join = NextJoin(b, b.idx, &join_order);
  const long limit = join >= 0 ? join - 1 : n - 1;
  const long run_end = RunEnd(b, b.idx + 1, at, limit);
  if (run_end > b.idx) Release(b, run_end, -1, out);
  const long here = std::max(run_end, b.idx);
  if (b.idx < here) return;  // still to reach (or work at) the waypoints here
  if (b.idx >= 0 && t < Departure(b, b.idx)) {
    WakeAt(Departure(b, b.idx));  // nothing but time keeps it here
    ctl.SetWorking(r, IsStop(w[static_cast<std::size_t>(b.idx)]), Departure(b, b.idx));
    return;
  }
  ctl.SetWorking(r, false);
  if (join >= 0 && here == join - 1) {  // at the rendezvous approach: join the team
    // Only next to the rendezvous point: from there its drive to the slot stays inside the
    // team's envelope. A back-off or nudge may have left it farther (the plan continues from
    // where it ended): it drives back first. Found by the safety check on a dense grid: a
    // member backed off one point joined there and drove to its slot through the point
    // between, where another robot stood (0.000 m).
    const PointId p = w[static_cast<std::size_t>(join)].point;
    bool next_to = at == p;
    for (ArcId a : map->out_arcs(at)) next_to = next_to || map->arc(a).to == p;
    if (!next_to) {
      auto path = routes->Path(at, p);
      if (path.ok() && path->points.size() > 2) {
        RewriteLeg(b, here, path->points, join, t, out);
        b.leg_stale = true;
        return;
      }
    }
    JoinTeam(b, join_order, t, out);
    return;
  }
  if (!b.paused_by.empty() && ctl.Next(r) == kNoPoint) HoldPaused(b, out);  // also idle: it says so
  if (here + 1 >= n) {  // nothing ahead: idle
    ctl.SetIdle(r, true);
    bool aside = false;
    if (!ctl.HasRoute(r) && !b.stepped_aside && b.paused_by.empty() &&
        (blocks_service[static_cast<std::size_t>(at)] || ctl.InExclusiveCorridor(at))) {
      // Out of the way of the next robot to serve here (or to pass through the one-robot
      // corridor it stands in): a siding nearby, else home.
      aside = ctl.StepAside(r, {at});
      if (!aside && b.home != kNoPoint && b.home != at) {
        auto path = routes->Path(at, b.home);
        aside = path.ok() && ctl.SetRoute(r, path->points).ok();
      }
    }
    if (aside) {
      b.stepped_aside = true;
      RewriteLeg(b, here, ctl.RemainingRoute(r), -1, t, out);  // a nudge: moves appended
      CopyLeg(b);
      b.leg_stop = -1;
      b.leg_stale = false;
    }
    if (!ctl.HasRoute(r)) return;
    if (b.leg_stale || !LegIsRemainingRoute(b)) {
      // The controller moves it (a nudge or back-off in deadlock breaking): the plan follows.
      RewriteLeg(b, here, ctl.RemainingRoute(r), -1, t, out);
      CopyLeg(b);
      b.leg_stop = -1;
      b.leg_stale = false;
    }
  } else {
    ctl.SetIdle(r, false);
    b.stepped_aside = false;
  }
  if (b.leg_stale || !ctl.HasRoute(r)) {
    if (here + 1 < n) {
      // The leg: from here to the next stop (or the join approach, or the plan's end).
      long stop = here + 1;
      while (stop < limit && !IsStop(w[static_cast<std::size_t>(stop)])) ++stop;
      std::vector<PointId> leg{at};
      for (long i = here + 1; i <= stop; ++i) {
        const PointId p = w[static_cast<std::size_t>(i)].point;
        if (p != leg.back()) leg.push_back(p);
      }
      const bool from_plan = here >= 0 && w[static_cast<std::size_t>(here)].point == at;
      // An unchanged leg keeps the robot's place in the grant queues.
      const bool same = from_plan && ctl.RemainingRouteIs(r, leg);
      if (!same && (!from_plan || !ctl.SetRoute(r, leg).ok())) {
        // The robot is not where its plan continues (restart, reconnect elsewhere, a fresh
        // plan from another point): route from where it stands to the stop.
        auto path = routes->Path(at, w[static_cast<std::size_t>(stop)].point);
        if (!path.ok() || !ctl.SetRoute(r, path->points).ok()) {
          Hold(b, "no route from '" + map->point(at).name + "' to '" +
                      map->point(w[static_cast<std::size_t>(stop)].point).name + "'", out);
          return;
        }
        stop = RewriteLeg(b, here, path->points, stop, t, out);
      }
      b.leg_stop = stop;
    }
    CopyLeg(b);
    b.leg_stale = false;
    if (!ctl.HasRoute(r)) return;
  }
  if (AwaitsItsTurn(b, t, out)) return;
  RequestSolo(b, t, out);
}

void GateImpl::RequestSolo(GateBot& b, double t, std::vector<GateEffect>& out) {
  if (!b.paused_by.empty()) return HoldPaused(b, out);
  const auto r = static_cast<std::size_t>(b.ctl);
  for (int attempt = 0; attempt < 3; ++attempt) {
    const TrafficDecision d = ctl.Request(r, t);
    if (d == TrafficDecision::kGo) {
      b.left = false;
      b.blocked = false;
      const PointId next = ctl.Next(r);
      Release(b, GrantedRunEnd(b, ctl.At(r), next), map->IntersectionOf(next), out);
      return;
    }
    if (d == TrafficDecision::kWait) {
      Hold(b, ctl.why(r), out);
      return;
    }
    if (d == TrafficDecision::kBlocked) {
      Block(b, ctl.why(r), out);
      return;
    }
    AdoptRoute(b, t, out);  // kReplanned: the controller's detour becomes the leg
  }
}

void GateImpl::Block(GateBot& b, const std::string& why, std::vector<GateEffect>& out) {
  if (!b.blocked) {
    b.blocked = true;
    GateEffect e;
    e.kind = GateEffect::Kind::kBlocked;
    e.robot = b.id;
    e.reason = why;
    out.push_back(std::move(e));
  }
  Hold(b, "blocked: " + why, out);
}

// The controller changed a standing solo robot's route (detour, back-off, nudge): rewrite
// its leg's waypoints to match. A route that ends at the leg's stop replaces the leg; one that
// ends elsewhere (a back-off, a nudge) is driven first and the plan continues from its end.
void GateImpl::AdoptRoute(GateBot& b, double t, std::vector<GateEffect>& out) {
  const auto r = static_cast<std::size_t>(b.ctl);
  const std::vector<PointId> route = ctl.RemainingRoute(r);
  if (route == b.leg || route.size() < 2) return;
  const long n = static_cast<long>(b.plan.waypoints.size());
  const long here = std::max(b.idx, RunEnd(b, b.idx + 1, ctl.At(r), n - 1));
  const long stop = b.leg_stop;
  const bool to_stop = stop > here && stop < n &&
                       b.plan.waypoints[static_cast<std::size_t>(stop)].point == route.back();
  const long resume = to_stop ? stop : (here + 1 < n ? here + 1 : -1);
  const long resumed = RewriteLeg(b, here, route, resume, t, out);
  if (to_stop) {
    b.leg_stop = resumed;
    b.leg_stale = false;
  } else {
    b.leg_stop = -1;
    b.leg_stale = resume >= 0;  // after the detour, route back into the plan
  }
  b.leg = route;
  b.leg_epoch = 0;
}

void GateImpl::OnReached(GateBot& b, std::uint64_t seq, double t) {
  if (seq <= b.reached_seq) return;
  const long i = IndexOf(b, seq);
  b.reached_seq = seq;
  b.reach_time = t;
  if (i < 0) {  // not in the plan (any more): the last waypoint before it
    Reindex(b);
    return;
  }
  b.idx = i;
  if (b.team.empty() && OnFloor(b)) {
    const auto r = static_cast<std::size_t>(b.ctl);
    const PointId p = b.plan.waypoints[static_cast<std::size_t>(i)].point;
    if (p != ctl.At(r) && p != ctl.Next(r)) {
      // Somewhere the controller did not send it (it drove on a release of the dispatcher
      // before a restart): the controller follows the robot, and the leg is re-planned.
      ctl.Remove(r);
      if (!PlaceBot(b, p)) PlaceNear(b);
      b.leg_stale = true;
      return;
    }
    if (ctl.Next(r) != kNoPoint && p == ctl.Next(r)) {
      ctl.Arrived(r, t);
      CopyLeg(b);
      b.stepped_aside = false;  // idle where it arrived: may have to step aside again
      // Out of the formation's envelope around where it left the team: one agent of its own.
      const double envelope = config.point_clearance + FormationRadius();
      // A robot of one of the teams it left (every one it forgets below), in it or left it
      // too, whichever of its own former teams that is for it (found by the safety check:
      // a former teammate whose newest former team was another was not looked at).
      auto former_mate = [&](const GateBot& o) {
        if (&o == &b) return false;
        for (const std::string* k : {&b.former_team, &b.older_former, &b.oldest_former}) {
          if (k->empty()) continue;
          if (o.team == *k || o.former_team == *k || o.older_former == *k || o.oldest_former == *k) return true;
        }
        return false;
      };
      auto teammates_out = [&] {  // nobody of its former team still stands in a slot there
        if (b.former_at == kNoPoint) return true;
        const Eigen::Vector2d& d = map->point(b.former_at).position;
        for (const auto& [id, o] : bots) {
          if (&o == &b || (o.former_team != b.former_team && o.team != b.former_team)) continue;
          if (!o.has_xy || (o.xy - d).norm() < envelope - 1e-9) return false;
        }
        return true;
      };
      // Nor beside one of them where it arrived, or where one of them drives to: exempt from
      // them, it may have driven up to one closer than eps1, or one may have been let drive up to
      // it (found by the safety check: a member of a broken-up team arrived 0.400 m from a former
      // teammate and lost the exemption there; Tables 1+2 x10 at 0.4 s steps, a former teammate
      // was sent, in the step it arrived, to a point 0.500 m from it).
      auto none_beside = [&] {
        const Eigen::Vector2d& here = map->point(ctl.At(r)).position;
        for (const auto& [id, o] : bots) {
          if (!former_mate(o)) continue;
          if (o.has_xy && (o.xy - here).norm() < config.point_clearance - 1e-9) return false;
          const PointId next = o.ctl >= 0 && !ctl.removed(static_cast<std::size_t>(o.ctl))
                                   ? ctl.Next(static_cast<std::size_t>(o.ctl))
                                   : kNoPoint;
          if (next != kNoPoint && (map->point(next).position - here).norm() < config.point_clearance - 1e-9) {
            return false;
          }
        }
        return true;
      };
      if (!b.former_team.empty() && !teams.count(b.former_team) &&
          (b.former_at == kNoPoint ||
           (map->point(ctl.At(r)).position - map->point(b.former_at).position).norm() >= envelope - 1e-9) &&
          teammates_out() && none_beside()) {
        b.former_team.clear();
        b.older_former.clear();
        b.oldest_former.clear();
        ctl.SetEnvelope(r, 0.0);
        // At once: a former teammate asking later in this step is no longer exempt from it
        // (found by the safety check, Tables 1+2 x10 at 0.4 s steps: one was sent to a point
        // 0.500 m from it in the step it drove off its team).
        SetGroups(b);
      }
    }
  }
}

// --- Minimum distance ---------------------------------------------------------------------

// The formation orders a robot counts as one agent with: the team it is in or approaches,
// and the teams it left (at a drop, or broken up) until it (and its teammates) have driven off.
GateTeamKeys GateImpl::TeamKeys(const GateBot& b) const {
  GateTeamKeys keys;
  if (Alone(b)) return keys;
  const std::string* current = &b.team;
  if (current->empty()) {
    // The waypoint it drives to; before the first one is reached, the first after the anchor
    // (which serves no order).
    const long i = std::min<long>(std::max(b.idx + 1, 1L), static_cast<long>(b.plan.order_of.size()) - 1);
    if (i >= 0) {
      const std::string& o = b.plan.order_of[static_cast<std::size_t>(i)];
      if (!o.empty() && b.plan.teams.count(o)) current = &o;
    }
  }
  // The distinct ones of the team it is in or approaches, the team it left last and the one
  // before, in that order. All three count: found by the core's safety check (Table 1 ×5), a
  // member of two broken-up teams in turn that was given its next formation dropped the older
  // one and was 0.400 m from a teammate of that team still standing in its slot.
  std::size_t n = 0;
  for (const std::string* k : {current, &b.former_team, &b.older_former, &b.oldest_former}) {
    if (n == keys.size()) break;
    const auto end = keys.begin() + static_cast<std::ptrdiff_t>(n);
    if (!k->empty() && std::find(keys.begin(), end, *k) == end) keys[n++] = *k;
  }
  return keys;
}

void GateImpl::SetGroups(GateBot& b) {
  const auto r = static_cast<std::size_t>(b.ctl);
  if (Alone(b)) {  // no team keys: no strings built (every robot, every step)
    b.approach.clear();
    ctl.SetGroup(r, 0, 0, 0);
    return;
  }
  const GateTeamKeys keys = TeamKeys(b);
  b.approach = keys[0];
  auto group = [](const std::string& k) { return k.empty() ? 0 : GroupOf(k); };
  ctl.SetGroup(r, group(keys[0]), group(keys[1]), group(keys[2]));
}

}  // namespace dispatch::engine
