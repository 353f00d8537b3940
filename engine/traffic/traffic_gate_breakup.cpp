// TrafficGate: a formation team breaking up before its drop (its order cancelled, failed or put
// back after a block): its members leave the point one at a time (DissolveTeam, then
// StepLeaving in traffic_gate_leaving.cpp) or, with no way off, at once (BreakTeam); and who
// stays exempt from whom afterwards (BecomeFormer, TeammateBeside). The teams' other phases are
// in traffic_gate_teams.cpp.
#include <algorithm>
#include <limits>
#include <string>
#include <vector>

#include "engine/fleet/formation.h"
#include "engine/traffic/traffic_gate_impl.h"

namespace dispatch::engine {

void GateImpl::BecomeFormer(GateBot& b, const std::string& order, PointId at) {
  // Three keys at most (the controller's three groups). Found by the core's safety check
  // (Table 1 x5 with blocked robots back in service): a robot blocked on a team's point while
  // two members of that team stood in their slots around it (off the floor: the point was
  // its) was in two more teams in turn that broke up, dropped the first one and stood 0.231 m
  // from those members as a stranger.
  // Its former teams, newest first: the new one, then two of those it had, the ones with a
  // member still beside it first (found by the core's safety check, 300 random orders with
  // 20% formations: a member of three teams in turn dropped the oldest one while it stood
  // 0.400 m from a member of it).
  std::vector<std::string> kept;
  for (const std::string* o : {&b.former_team, &b.older_former, &b.oldest_former}) {
    if (!o->empty() && *o != order && std::find(kept.begin(), kept.end(), *o) == kept.end()) kept.push_back(*o);
  }
  // Closer than eps1 first: dropping that team makes the two strangers standing too close
  // (found by the core's safety check, Tables 1+2 x10 with the paper's formation settings: a
  // member with many formations queued was in three more teams that broke up at once, each
  // with a member within the envelope, and dropped the one whose member stood 0.400 m away).
  auto rank = [&](const std::string& o) {
    const double d = TeammateDistance(b, o);
    return d < config.point_clearance - 1e-9 ? 0 : (d < config.point_clearance + FormationRadius() - 1e-9 ? 1 : 2);
  };
  std::stable_sort(kept.begin(), kept.end(),
                   [&](const std::string& x, const std::string& y) { return rank(x) < rank(y); });
  kept.resize(std::min<std::size_t>(kept.size(), 2));
  b.older_former = kept.size() > 0 ? kept[0] : std::string();
  b.oldest_former = kept.size() > 1 ? kept[1] : std::string();
  b.former_team = order;
  b.former_at = at;
}

namespace {

// o is in team `order`, approaches it or has left it.
bool OfTeam(const GateBot& o, const std::string& order) {
  return o.team == order || o.former_team == order || o.older_former == order || o.oldest_former == order ||
         o.approach == order;
}

}  // namespace

bool GateImpl::TeammateBeside(const GateBot& b, const std::string& order) const {
  const double envelope = config.point_clearance + FormationRadius() - 1e-9;
  if (TeammateDistance(b, order) < envelope) return true;
  // Or it drives to a point beside one: granted while it was exempt from them, it arrives
  // there all the same (found through the service, the burst three at a time: a member on its
  // way to its rendezvous, its order given back as it drove up to a teammate, arrived a
  // stranger 0.400 m from it).
  if (!OnFloor(b)) return false;
  const PointId next = ctl.Next(static_cast<std::size_t>(b.ctl));
  return next != kNoPoint && TeamDistanceFrom(map->point(next).position, b, order) < envelope;
}

double GateImpl::TeammateDistance(const GateBot& b, const std::string& order) const {
  if (!b.has_xy) return std::numeric_limits<double>::infinity();
  return TeamDistanceFrom(b.xy, b, order);
}

double GateImpl::TeamDistanceFrom(const Eigen::Vector2d& p, const GateBot& b, const std::string& order) const {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& [id, o] : bots) {
    if (&o != &b && o.has_xy && OfTeam(o, order)) best = std::min(best, (o.xy - p).norm());
  }
  return best;
}

bool GateImpl::DissolveTeam(GateTeam& team) {
  // A team whose order went before its drop (cancelled, failed, put back after a block). If
  // its agent stands on a point with members in their slots, those leave that point one at a
  // time as after a drop (StepLeaving), under the agent's envelope until each has driven off:
  // broken up at once they would stay in their slots off the floor wherever the point was a
  // teammate's, unseen by the controller (strays: robots then waited in cycles no deadlock
  // breaking saw, and strangers drove up to them, Tables 1+2 x10 and 30% formation streams).
  const bool standing = TeamAgentOnFloor(team) && ctl.Next(static_cast<std::size_t>(team.ctl)) == kNoPoint;
  bool in_slots = false;
  for (const std::string& id : team.members) {
    const GateBot* m = Find(id);
    in_slots = in_slots || (m && m->team == team.order);
  }
  if (!standing || !in_slots) {
    BreakTeam(team);
    return true;
  }
  const PointId at = ctl.At(static_cast<std::size_t>(team.ctl));
  notes.push_back("formation " + team.order + " broken up: its members leave '" + map->point(at).name +
                  "' one at a time");
  for (const std::string& id : team.members) {  // not in the team yet: as in BreakTeam
    GateBot* m = Find(id);
    if (m && m->team.empty() && m->approach == team.order && TeammateBeside(*m, team.order)) {
      BecomeFormer(*m, team.order, at);
    }
  }
  // It drives no more: no route, no request queued for a grant, no wait of its own (it waits
  // on whoever holds the point a member leaves for: StepLeaving); never asked to yield, as when
  // it assembled, and as long as anyone would wait (its members leave around it).
  const auto tr = static_cast<std::size_t>(team.ctl);
  (void)ctl.SetRoute(tr, {at});
  ctl.WaitOn(tr, -1, 0.0, {});
  ctl.SetWorking(tr, true, 1e9);
  team.phase = GateTeam::Phase::kLeaving;
  team.broken = true;
  team.drop = at;
  return false;
}

void GateImpl::BreakTeam(GateTeam& team) {
  notes.push_back("formation " + team.order + " broken up");
  // Where the members stand in their slots (around the point the team agent last stood at):
  // each stays exempt from its former teammates until it has driven out of the envelope
  // around it and none of them is still standing there (OnReached), as after a drop. Found by
  // the core's safety check: a member that reached its next point 0.5 m from the team's point
  // lost the exemption while a teammate still stood in its slot there, and that teammate,
  // back on the floor, drove past it at 0.50 m.
  PointId at = kNoPoint;
  if (TeamAgentOnFloor(team)) {
    at = ctl.At(static_cast<std::size_t>(team.ctl));
    // Inside an intersection, the members in their slots take the team's grant over before
    // the agent lets it go: else a robot waiting for a crossing movement was granted it the
    // moment the agent was removed, around a member not back on the floor yet (found by the
    // core's safety check: 300 random orders with 30% formations, seed 5, 195.5 s).
    for (const std::string& id : team.members) {
      const GateBot* m = Find(id);
      if (m && m->team == team.order && m->ctl >= 0 && !OnFloor(*m)) ctl.HoldGrantAt(static_cast<std::size_t>(m->ctl), at);
    }
    ctl.Remove(static_cast<std::size_t>(team.ctl));
  }
  if (team.ctl >= 0) team_pool.push_back(static_cast<std::size_t>(team.ctl));
  team.ctl = -1;
  const int group = GroupOf(team.order);
  for (const std::string& id : team.members) {  // leader first
    auto it = bots.find(id);
    if (it == bots.end()) continue;
    GateBot& m = it->second;
    if (m.team.empty()) {
      // Not in the team yet: on its way to the rendezvous it was exempt from its teammates
      // (its controller group, TeamKeys) and may stand closer to one than eps1 now. It stays
      // exempt from them until it has driven off, as a member that had joined. Found by the
      // core's safety check: two members waiting 0.4 m apart for their rendezvous lost the
      // exemption at once. Only one that stands by a teammate, though: one still far from
      // them (stuck on its way) is a stranger to them from now on, or a member leaving its slot
      // was let drive up to it as to a teammate (found by the core's safety check: Tables 1+2
      // x10 with free members only, a member blocked 1.7 m from the rendezvous and a member
      // leaving its slot 0.400 m apart).
      if (m.approach == team.order && TeammateBeside(m, team.order)) BecomeFormer(m, team.order, at);
      continue;
    }
    if (m.team != team.order) continue;
    GateBot& b = m;
    b.team.clear();
    BecomeFormer(b, team.order, at);
    b.leg_stale = true;
    // It stands in its slot (D_f off the team's point) until it reports elsewhere: back on the
    // floor there at once, by its pose, before anyone is given the points the team agent held
    // (issue 15 §3b). If that point is a teammate's, the teammate's D_f envelope covers this
    // slot, and PlaceStrays places it once the point is free.
    if (!OnFloor(b) && b.has_xy && b.ctl >= 0) {
      const auto r = static_cast<std::size_t>(b.ctl);
      ctl.SetGroup(r, 0, group);
      if (PlaceBot(b, map->NearestPoint(b.xy))) ctl.SetEnvelope(r, FormationRadius());
    }
    if (!OnFloor(b)) {
      // A stray: the controller keeps strangers' points clear of where it stands.
      strays.insert(id);
      if (b.ctl >= 0 && b.has_xy) ctl.SetStanding(static_cast<std::size_t>(b.ctl), b.xy);
    }
  }
}

}  // namespace dispatch::engine
