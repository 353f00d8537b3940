// TrafficGate: formation teams after a restart (issue 4 §3, issue 15 §3b): the gate's teams are
// gone but the members' plans and positions are not; a member found inside its formation's
// segment forms the team again where it stands (see traffic_gate_impl.h, SpanAround and
// RejoinTeam). The teams' phases are in traffic_gate_teams.cpp.
#include <algorithm>
#include <string>

#include "engine/traffic/traffic_gate_impl.h"

namespace dispatch::engine {

std::optional<std::pair<std::string, GateImpl::TeamSpan>> GateImpl::SpanAround(const GateBot& b) const {
  if (!b.team.empty() || b.plan.teams.empty() || b.idx < 0) return std::nullopt;
  for (const auto& [order, members] : b.plan.teams) {
    auto team = teams.find(order);
    if (team == teams.end() || team->second.phase != GateTeam::Phase::kForming) continue;
    auto span = SpanOf(b, order);
    if (span && span->join <= b.idx && b.idx <= span->drop) return std::make_pair(order, *span);
  }
  return std::nullopt;
}

bool GateImpl::RejoinTeam(GateBot& b, const std::string& order, const TeamSpan& span, double t,
                          std::vector<GateEffect>& out) {
  GateTeam& team = teams.at(order);
  struct Member {
    GateBot* bot;
    std::optional<TeamSpan> span;  // none: its plan no longer holds the order
  };
  std::vector<Member> members;
  bool moved = false, left = false, all_back = true;
  for (const std::string& id : team.members) {
    auto m = bots.find(id);
    if (m == bots.end() || !m->second.connected || !m->second.synced) {
      all_back = false;
      continue;
    }
    Member v{&m->second, SpanOf(m->second, order)};
    // Off the first pick (members in lockstep may be a point apart), or off the drop.
    moved = moved || (v.span && v.bot->idx > v.span->first_pick);
    left = left || !v.span || v.bot->idx > v.span->drop;
    members.push_back(v);
  }
  auto hold = [&](const std::string& why) {
    if (!OnFloor(b)) PlaceNear(b);  // it keeps a point meanwhile
    Hold(b, "formation " + order + ": " + why, out);
    return true;
  };
  if (left) {  // the team was leaving its drop: the others leave as its former members
    const PointId d = b.plan.waypoints[static_cast<std::size_t>(span.drop)].point;
    for (const std::string& id : team.members) {
      auto m = bots.find(id);
      if (m == bots.end() || !m->second.team.empty()) continue;
      BecomeFormer(m->second, order, d);
    }
    BreakTeam(team);
    finished_teams.insert(order);
    teams.erase(order);
    ++leaving_ended;
    notes.push_back("formation " + order + " was leaving its drop: its members go on alone");
    return false;
  }
  if (!moved) {  // assembling: it joins (or is in its slot already) as it would have
    // (Near the rendezvous point the agent may hold every point it could be placed at.)
    if (!TeamAgentOnFloor(team) && !OnFloor(b) && !PlaceNear(b)) return true;
    JoinTeam(b, order, t, out);
    return true;
  }
  // Moving: every member must be back; the team agent stands at the least advanced member's
  // point and drives to the most advanced one's (the lockstep step they were in).
  if (!all_back) return hold("waiting for every member to report");
  long k = -1, k_ahead = -1;
  for (const Member& v : members) {
    if (v.bot->idx < v.span->first_pick) return hold(v.bot->id + " is not in the formation's segment");
    const long mk = v.bot->idx - v.span->first_pick;
    k = k < 0 ? mk : std::min(k, mk);
    k_ahead = std::max(k_ahead, mk);
  }
  auto point_at = [&](long i) { return b.plan.waypoints[static_cast<std::size_t>(span.first_pick + i)].point; };
  const PointId p = point_at(k);
  const bool agent_was_on_floor = TeamAgentOnFloor(team);
  const PointId agent_at = agent_was_on_floor ? ctl.At(static_cast<std::size_t>(team.ctl)) : kNoPoint;
  auto undo = [&](const std::string& why) {
    if (TeamAgentOnFloor(team)) ctl.Remove(static_cast<std::size_t>(team.ctl));
    if (agent_was_on_floor) (void)ctl.Place(static_cast<std::size_t>(team.ctl), agent_at);
    for (const Member& v : members) {
      if (v.bot->team.empty() && !OnFloor(*v.bot)) PlaceNear(*v.bot);
    }
    return hold(why);
  };
  for (const Member& v : members) {  // the team agent stands for them from now on
    if (v.bot->team.empty() && OnFloor(*v.bot)) ctl.Remove(static_cast<std::size_t>(v.bot->ctl));
  }
  if (agent_was_on_floor) ctl.Remove(static_cast<std::size_t>(team.ctl));
  if (!PlaceTeamAgent(team, p, t)) return undo("point '" + map->point(p).name + "' is occupied");
  const auto tr = static_cast<std::size_t>(team.ctl);
  if (k_ahead > k) {  // the members ahead stand on a point the agent must hold too
    std::vector<PointId> leg{p};
    for (long i = k + 1; i <= k_ahead; ++i) {
      if (point_at(i) != leg.back()) leg.push_back(point_at(i));
    }
    if (leg.size() > 1) {
      ctl.SetWorking(tr, false);
      if (!ctl.SetRoute(tr, leg).ok() || ctl.Request(tr, t) != TrafficDecision::kGo) {
        return undo("point '" + map->point(leg[1]).name + "' is taken");
      }
      team.next_k = k_ahead;
      ctl.CopyRemainingRoute(tr, team.leg);
    }
  }
  for (const Member& v : members) {
    v.bot->team = order;
    v.bot->leg_stale = true;
    team.joined.insert(v.bot->id);
    if (k_ahead > k) Release(*v.bot, v.span->first_pick + k_ahead, -1, out);  // on to the step's end
  }
  notes.push_back("formation " + order + " formed again at '" + map->point(p).name + "' (its waypoint " +
                  std::to_string(k + 1) + " of " + std::to_string(span.drop - span.first_pick + 1) + ")" +
                  (k_ahead > k ? ", driving on to its waypoint " + std::to_string(k_ahead + 1) : ""));
  return true;
}

}  // namespace dispatch::engine
