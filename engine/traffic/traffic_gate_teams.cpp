// TrafficGate: formation teams (Chu2024 §3.2; issue 4 §3: "the traffic controller treats the
// formation as one agent with its envelope; grants are held for the whole formation").
// See traffic_gate.h for the phases: forming at the rendezvous point, moving as one agent,
// leaving the drop point one member at a time (traffic_gate_leaving.cpp); breaking up before
// the drop is in traffic_gate_breakup.cpp.
#include <algorithm>
#include <cstdio>
#include <cmath>
#include <string>

#include "engine/fleet/formation.h"
#include "engine/traffic/traffic_gate_impl.h"

namespace dispatch::engine {

namespace {

// A member's formation index -> plan index, or -1 when its plan no longer holds the order.
struct MemberView {
  GateBot* bot = nullptr;
  long first_pick = -1;  // plan index of formation index 0
  long length = 0;       // formation waypoints
};

}  // namespace

void GateImpl::SyncTeams(GateBot& b) {
  std::set<std::string> in_plan(b.plan.order_of.begin(), b.plan.order_of.end());
  for (const auto& [order, members] : b.plan.teams) {
    if (!in_plan.count(order) || members.size() != static_cast<std::size_t>(kFormationTeamSize)) continue;
    if (finished_teams.count(order)) continue;  // its drop is done (a late drop report may follow)
    GateTeam& team = teams[order];
    if (team.order.empty()) {
      team.order = order;
      team.members = members;
    }
  }
  // The team it has joined lost its order: after the drop (the plan was trimmed) the team
  // leaves; before it (cancelled, failed) it breaks up.
  if (!b.team.empty() && !in_plan.count(b.team)) {
    auto it = teams.find(b.team);
    if (it == teams.end()) {
      b.team.clear();
    } else {
      auto drop = it->second.drop_seq.find(b.id);
      if (drop != it->second.drop_seq.end() && b.reached_seq >= drop->second) {
        it->second.phase = GateTeam::Phase::kLeaving;
      } else if (it->second.phase != GateTeam::Phase::kLeaving) {
        if (DissolveTeam(it->second)) teams.erase(it);
      }
    }
  }
  // A forming team one of whose members lost the order cannot form any more.
  for (auto it = teams.begin(); it != teams.end();) {
    GateTeam& team = it->second;
    const bool mine = std::find(team.members.begin(), team.members.end(), b.id) != team.members.end();
    if (mine && team.phase == GateTeam::Phase::kForming && !in_plan.count(team.order)) {
      if (DissolveTeam(team)) {
        it = teams.erase(it);
      } else {
        ++it;
      }
    } else {
      ++it;
    }
  }
}

void GateImpl::JoinTeam(GateBot& b, const std::string& order, double t, std::vector<GateEffect>& out) {
  auto it = teams.find(order);
  auto span = SpanOf(b, order);
  if (it == teams.end() || !span) return;
  GateTeam& team = it->second;
  if (team.phase != GateTeam::Phase::kForming) return;
  const PointId p = span->rendezvous;
  if (!TeamAgentOnFloor(team)) {
    if (!OnFloor(b)) return;
    const auto r = static_cast<std::size_t>(b.ctl);
    const bool on_p = ctl.At(r) == p;
    if (on_p) ctl.Remove(r);  // it stands on the rendezvous point itself: the team takes it over
    if (!PlaceTeamAgent(team, p, t)) {
      if (on_p) (void)ctl.Place(r, p);
      // The controller sees the wait: if whoever is in the way waits on b in turn (it needs
      // the point b stands on), that is a cycle it breaks.
      const int blocker = ctl.BlockerOf(p, r, FormationRadius());
      const std::string why = "formation " + order + ": rendezvous point '" + map->point(p).name + "' is occupied";
      ctl.WaitOn(r, blocker, t, blocker >= 0 ? why + " by " + ctl.robot_id(static_cast<std::size_t>(blocker)) : why);
      // Never for ever: found on a dense grid, an idle robot boxed in next to the rendezvous
      // point (by the team's own strays and a queue of waiting robots) kept a team forming
      // until the run's end. Blocked, the member gives its orders back (re-allocated). Timed
      // here: a member standing on the rendezvous point is taken off and put back each try,
      // which restarts the controller's wait clock.
      if (b.forming != order || t - b.forming_last > 1.0) {
        b.forming = order;
        b.forming_since = t;
      }
      b.forming_last = t;
      if (blocker >= 0 && t - b.forming_since >= config.blocked_after) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "blocked after waiting %.0f s: ", t - b.forming_since);
        b.forming.clear();
        Block(b, buf + ctl.why(r), out);
        return;
      }
      Hold(b, why, out);
      return;
    }
    ctl.WaitOn(r, -1, t, {});
  }
  b.forming.clear();
  // Into its slot: the rendezvous run up to the formation's first pick. It keeps its point
  // until it is clear of it (StepTeams), then the team agent stands for it.
  Release(b, span->first_pick, map->IntersectionOf(p), out);
  b.team = order;
  b.leg_stale = true;
  team.joined.insert(b.id);
}

bool GateImpl::PlaceTeamAgent(GateTeam& team, PointId p, double t) {
  bool placed = false;
  const int group = GroupOf(team.order);
  if (team.ctl >= 0) {
    ctl.SetGroup(static_cast<std::size_t>(team.ctl), group);
    placed = ctl.Place(static_cast<std::size_t>(team.ctl), p).ok();
  } else if (!team_pool.empty()) {
    const std::size_t pooled = team_pool.back();
    ctl.SetGroup(pooled, group);
    placed = ctl.Place(pooled, p).ok();
    if (placed) {
      team_pool.pop_back();
      team.ctl = static_cast<int>(pooled);
    }
  } else {
    auto added = ctl.AddRobot("formation-" + std::to_string(++team_agents), p, group);
    placed = added.ok();
    if (placed) team.ctl = static_cast<int>(*added);
  }
  if (!placed) return false;
  const auto tr = static_cast<std::size_t>(team.ctl);
  ctl.SetIdle(tr, false);
  ctl.SetEnvelope(tr, FormationRadius());
  ctl.SetWorking(tr, true, t + 3600.0);  // assembling: never asked to yield
  return true;
}

bool GateImpl::TeamAgentOnFloor(const GateTeam& team) const {
  return team.ctl >= 0 && !ctl.removed(static_cast<std::size_t>(team.ctl));
}

void GateImpl::StepTeams(double t, std::vector<GateEffect>& out) {
  std::vector<std::string> resync;  // broken teams gone: their order may have a new team by now
  for (auto it = teams.begin(); it != teams.end();) {
    GateTeam& team = it->second;
    // Members as they stand now.
    std::vector<MemberView> m;
    bool complete = true;
    for (const std::string& id : team.members) {
      auto b = bots.find(id);
      if (b == bots.end()) {
        complete = false;
        break;
      }
      MemberView v;
      v.bot = &b->second;
      auto span = SpanOf(b->second, team.order);
      if (span) {
        v.first_pick = span->first_pick;
        v.length = span->drop - span->first_pick + 1;
        team.drop_seq[id] = span->seq_drop;
        if (!team.broken) team.drop = b->second.plan.waypoints[static_cast<std::size_t>(span->drop)].point;
      }
      m.push_back(v);
    }
    if (!complete) {
      ++it;
      continue;
    }
    // Joined members leave the controller once clear of the point they joined from.
    for (const MemberView& v : m) {
      GateBot& b = *v.bot;
      if (b.team != team.order || !OnFloor(b)) continue;
      const auto r = static_cast<std::size_t>(b.ctl);
      const bool clear = !b.has_xy || (b.xy - map->point(ctl.At(r)).position).norm() >= config.point_clearance;
      if (clear || (v.first_pick >= 0 && b.idx >= v.first_pick - 1)) ctl.Remove(r);
    }
    if (team.phase == GateTeam::Phase::kForming) {
      bool ready = team.joined.size() == team.members.size();
      for (const MemberView& v : m) ready = ready && v.first_pick >= 0 && v.bot->idx >= v.first_pick;
      if (!ready) {
        // The assembling agent waits on a member still on its way: a robot that holds that
        // member up while it waits for the team's point closes a cycle the controller breaks.
        if (TeamAgentOnFloor(team)) {
          int awaited = -1;
          for (const MemberView& v : m) {
            if (awaited < 0 && v.bot->team != team.order && OnFloor(*v.bot)) awaited = v.bot->ctl;
          }
          ctl.WaitOn(static_cast<std::size_t>(team.ctl), awaited, t,
                     awaited >= 0 ? "formation " + team.order + " waits for " + ctl.robot_id(static_cast<std::size_t>(awaited)) : "");
        }
        ++it;
        continue;
      }
      if (TeamAgentOnFloor(team)) ctl.WaitOn(static_cast<std::size_t>(team.ctl), -1, t, {});
      team.phase = GateTeam::Phase::kMoving;
      // From the first pick (formed again after a restart: where the last member is).
      team.k = m[0].bot->idx - m[0].first_pick;
      for (const MemberView& v : m) team.k = std::min(team.k, v.bot->idx - v.first_pick);
      team.leg_stale = true;
      ctl.SetLoaded(static_cast<std::size_t>(team.ctl), true);
    }
    const auto tr = static_cast<std::size_t>(team.ctl);
    if (team.phase == GateTeam::Phase::kMoving) {
      long length = m[0].length;
      for (const MemberView& v : m) length = std::min(length, v.length);
      bool members_ok = length > 0;
      for (const MemberView& v : m) members_ok = members_ok && v.first_pick >= 0;
      if (!members_ok) {  // the drop was trimmed already: the team has arrived
        team.phase = GateTeam::Phase::kLeaving;
      } else {
        const GateBot& lead = *m[0].bot;
        auto point_at = [&](long k) { return lead.plan.waypoints[static_cast<std::size_t>(m[0].first_pick + k)].point; };
        auto run_end = [&](long k) {
          const PointId p = point_at(k);
          while (k + 1 < length && point_at(k + 1) == p) ++k;
          return k;
        };
        auto release_all = [&](long k, int intersection) {
          for (const MemberView& v : m) Release(*v.bot, v.first_pick + k, intersection, out);
        };
        auto all_reached = [&](long k) {
          for (const MemberView& v : m) {
            if (v.bot->idx < v.first_pick + k) return false;
          }
          return true;
        };
        const PointId next = ctl.Next(tr);
        if (next != kNoPoint) {
          if (!team.left) {
            // Every member clear of the point by eps2 (Chu2024 eq. (11)): whoever is given the
            // point next (a single robot, or a formation's centre) keeps its distance.
            const Eigen::Vector2d& at = map->point(ctl.At(tr)).position;
            bool clear = true;
            for (const MemberView& v : m) {
              clear = clear && v.bot->has_xy &&
                      (v.bot->xy - at).norm() >= config.point_clearance + FormationRadius();
            }
            if (clear) {
              ctl.LeftPoint(tr);
              team.left = true;
            }
          }
          if (team.next_k >= 0 && all_reached(team.next_k)) {
            ctl.Arrived(tr, t);
            team.k = team.next_k;
            team.next_k = -1;
            ctl.CopyRemainingRoute(tr, team.leg);
          }
        }
        if (ctl.Next(tr) == kNoPoint) {
          const long rk = run_end(team.k);
          release_all(rk, -1);
          double departure = 0.0;
          for (const MemberView& v : m) departure = std::max(departure, Departure(*v.bot, v.first_pick + rk));
          const bool done_here = all_reached(rk);
          if (done_here && t < departure) WakeAt(departure);
          if (done_here && t >= departure) {
            ctl.SetWorking(tr, false);
            if (rk + 1 >= length) {
              team.phase = GateTeam::Phase::kLeaving;
            } else {
              if (team.leg_stale || !ctl.HasRoute(tr)) {
                long s = rk + 1;
                while (s + 1 < length &&
                       !IsStop(lead.plan.waypoints[static_cast<std::size_t>(m[0].first_pick + s)])) {
                  ++s;
                }
                std::vector<PointId> leg{point_at(rk)};
                for (long k = rk + 1; k <= s; ++k) {
                  if (point_at(k) != leg.back()) leg.push_back(point_at(k));
                }
                if (!ctl.SetRoute(tr, leg).ok()) {
                  for (const MemberView& v : m) Hold(*v.bot, "formation " + team.order + ": bad route", out);
                  ++it;
                  continue;
                }
                ctl.CopyRemainingRoute(tr, team.leg);
                team.leg_stop = s;
                team.leg_stale = false;
              }
              const MemberView* paused = nullptr;
              for (const MemberView& v : m) {
                if (!v.bot->paused_by.empty()) paused = &v;
              }
              if (paused) {  // the team waits for its paused member
                for (const MemberView& v : m) {
                  if (v.bot->paused_by.empty()) {
                    Hold(*v.bot, "formation " + team.order + ": " + paused->bot->id + " paused", out);
                  } else {
                    HoldPaused(*v.bot, out);
                  }
                }
                ++it;
                continue;
              }
              const TrafficDecision d = ctl.Request(tr, t);
              if (d == TrafficDecision::kGo) {
                team.left = false;
                team.blocked = false;
                const PointId to = ctl.Next(tr);
                long nk = rk + 1;
                while (nk < length && point_at(nk) != to) ++nk;
                team.next_k = nk < length ? nk : -1;
                if (team.next_k >= 0) release_all(run_end(team.next_k), map->IntersectionOf(to));
              } else if (d != TrafficDecision::kReplanned) {  // a detour is adopted after deadlocks
                const std::string why = (d == TrafficDecision::kBlocked ? "blocked: " : "") + ctl.why(tr);
                if (d == TrafficDecision::kBlocked && !team.blocked) {
                  team.blocked = true;
                  GateEffect e;
                  e.kind = GateEffect::Kind::kBlocked;
                  e.robot = team.members.front();
                  e.reason = "formation " + team.order + ": " + ctl.why(tr);
                  out.push_back(std::move(e));
                }
                for (const MemberView& v : m) Hold(*v.bot, "formation " + team.order + ": " + why, out);
              }
            }
          } else if (done_here || all_reached(team.k)) {
            ctl.SetWorking(tr, true, departure);
          }
        }
      }
    }
    if (team.broken && team.broken_since < 0) team.broken_since = t;
    if (team.broken && t - team.broken_since > config.t_w2) {  // broken teams are always leaving
      // Its members found no way off within T_w2 (the points around held by robots that wait
      // for the team, or blocked): it breaks up where it stands, as before (BreakTeam).
      notes.push_back("formation " + team.order + ": no way off '" + map->point(team.drop).name + "' for " +
                      std::to_string(static_cast<int>(config.t_w2)) + " s");
      BreakTeam(team);
      resync.push_back(team.order);
      it = teams.erase(it);
      ++leaving_ended;
      continue;
    }
    if (team.phase == GateTeam::Phase::kLeaving && StepLeaving(team, t, out)) {
      const bool broken = team.broken;
      const std::string order = team.order;
      if (broken) {
        resync.push_back(order);
      } else {
        finished_teams.insert(order);
      }
      it = teams.erase(it);
      ++leaving_ended;
      continue;
    }
    ++it;
  }
  for (const std::string& order : resync) {
    for (GateBot* b : in_order) {
      if (b->plan.teams.count(order)) SyncTeams(*b);
    }
  }
}

// A detour of a moving team (head-on, timeouts, deadlocks): every member's waypoints follow
// the new centre route with its rigid offset (eq. (9)) for each segment's heading, turning in
// place where the heading changes (RewriteLeg).
void GateImpl::StepTeamsAfterDeadlocks(double t, std::vector<GateEffect>& out) {
  for (auto& [order, team] : teams) {
    if (team.phase != GateTeam::Phase::kMoving || team.ctl < 0) continue;
    const auto tr = static_cast<std::size_t>(team.ctl);
    if (ctl.removed(tr) || ctl.Next(tr) != kNoPoint) continue;
    const std::vector<PointId> route = ctl.RemainingRoute(tr);
    if (route.size() < 2 || route == team.leg) continue;
    for (std::size_t i = 0; i < team.members.size(); ++i) {
      auto b = bots.find(team.members[i]);
      if (b == bots.end()) continue;
      GateBot& bot = b->second;
      auto span = SpanOf(bot, order);
      if (!span) continue;
      const long length = span->drop - span->first_pick + 1;
      const PointId here_point = route.front();
      long rk = team.k;
      while (rk + 1 < length &&
             bot.plan.waypoints[static_cast<std::size_t>(span->first_pick + rk + 1)].point == here_point) {
        ++rk;
      }
      const long stop = team.leg_stop;
      const bool to_stop = stop > rk && stop < length &&
                           bot.plan.waypoints[static_cast<std::size_t>(span->first_pick + stop)].point == route.back();
      const long resume = to_stop ? span->first_pick + stop : span->first_pick + rk + 1;
      RewriteLeg(bot, span->first_pick + rk, route, resume < static_cast<long>(bot.plan.waypoints.size()) ? resume : -1,
                 t, out, static_cast<int>(i));
    }
    // The new stop's formation index is the same for every member (same rewrite).
    auto lead = bots.find(team.members.front());
    if (lead != bots.end()) {
      auto span = SpanOf(lead->second, order);
      if (span) {
        long s = -1;
        for (long k = team.k; k < span->drop - span->first_pick + 1; ++k) {
          if (lead->second.plan.waypoints[static_cast<std::size_t>(span->first_pick + k)].point == route.back()) {
            s = k;
            break;
          }
        }
        team.leg_stop = s;
      }
    }
    team.leg = route;
    team.leg_stale = false;
  }
}

}  // namespace dispatch::engine
