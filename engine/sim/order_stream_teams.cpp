// Order-stream simulation: formation orders (Chu2024 §3.2; issue 4 §3), the same model as
// TrafficGate's teams (engine/traffic/traffic_gate.h) on the simulator's own motion.
//
//  - Gathering: once all three have the order first in their queues (the rendezvous is
//    called), each member drives alone to the first pick P, leaving so as to arrive with the
//    slowest; until then it waits like an idle robot. The first to stand on P hands it to the
//    team's agent (one controller agent with the formation's envelope D_f, "working" so never
//    asked to yield) and drives into its slot; the others join from the point before P. A
//    joined member leaves the controller once clear of its point: the agent stands for it.
//  - Moving: when all three are in their slots the agent serves the order's stops like a single
//    robot (work at every pick and the drop) under the controller, with every grant and point
//    held for the whole formation; the members keep their slots around it (eq. (9)), and the
//    structure turns in place about its centre before an arc with a new heading.
//  - Leaving: after the drop's work the members go back into the controller while the agent
//    still holds the drop point D: each but the last is placed at the first point of its onward
//    route (or a free neighbour of D) and drives there from its slot; the last one takes D
//    itself from the agent once the others have arrived. With no room to leave for
//    blocked_after, the members still in their slots leave the floor as faulted. Former
//    teammates stay exempt from one another until each is eps1 from the others.
// A formation whose order fails before it moves (a member blocked or unreachable, or P kept
// occupied for blocked_after) breaks up: joined members leave P as at a drop. So does a
// formation whose agent is blocked on its way (the order fails): its members leave it where it
// stands and go on alone.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "engine/fleet/formation.h"
#include "engine/sim/order_stream_impl.h"

namespace dispatch::engine::stream_sim {

void StreamSim::EnqueueTeam(const std::vector<std::size_t>& members, std::size_t k) {
  const Order& o = orders_[k];
  const std::size_t ti = teams_.size();
  Team team;
  team.order = outcome_of_[k];
  team.members = members;
  team.group = static_cast<int>(ti) + 1;
  team.task.order = team.order;
  team.task.picks = o.picks;
  team.task.drop = o.drop;
  team.task.work = config_.allocation.work_time_override.value_or(o.work_time);
  team.task.team = static_cast<int>(ti);
  // The structure faces along its first arc out of P (formation.h: member 0 in front).
  const PointId p = o.picks.front();
  const PointId next = o.picks.size() > 1 ? o.picks[1] : o.drop;
  auto path = routes_->Path(p, next);
  if (path.ok() && path->points.size() >= 2) {
    const Eigen::Vector2d dir = map_->point(path->points[1]).position - map_->point(p).position;
    team.heading0 = std::atan2(dir.y(), dir.x());
  }
  StreamOrderOutcome& oc = out_.orders[team.order];
  oc.robot = bots_[members.front()].id;
  for (std::size_t m : members) oc.team.push_back(bots_[m].id);
  teams_.push_back(std::move(team));
  active_teams_.push_back(ti);
  for (std::size_t i = 0; i < members.size(); ++i) {
    Bot& b = bots_[members[i]];
    Task task = teams_[ti].task;
    task.member = static_cast<int>(i);
    b.parked_aside = false;
    b.tasks.push_back(std::move(task));
    ctl_.SetIdle(members[i], false);
    SyncGroup(members[i]);
  }
}

void StreamSim::SyncGroup(std::size_t r) {
  Bot& b = bots_[r];
  if (b.agent) return;
  if (b.slot == Slot::kNone) b.team = b.tasks.empty() ? -1 : b.tasks.front().team;
  const auto group = [&](int team) { return team >= 0 ? teams_[static_cast<std::size_t>(team)].group : 0; };
  ctl_.SetGroup(r, group(b.team), group(b.former));
}

void StreamSim::KeepFormer(Bot& b, int team) {
  // One former team at a time (the controller has two groups: the current team and this
  // one). An older one whose members are not apart yet stays while b is still near one of
  // them; else the team it leaves now, whose members stand right beside it, takes its place.
  if (b.former >= 0 && !teams_[static_cast<std::size_t>(b.former)].apart) {
    const std::size_t me = static_cast<std::size_t>(&b - bots_.data());
    for (std::size_t m : teams_[static_cast<std::size_t>(b.former)].members) {
      if (m == me || bots_[m].removed || bots_[m].former != b.former) continue;
      if ((Position(m) - Position(me)).norm() < clearance_ - 1e-9) return;
    }
  }
  b.former = team;
}

void StreamSim::MemberStart(std::size_t r, double t, PointId& start, double& ready) const {
  const Bot& b = bots_[r];
  const Team& team = teams_[static_cast<std::size_t>(b.team)];
  ready = t;
  if (b.slot == Slot::kOut) {
    start = ctl_.At(r);
    ready += (b.len - b.s) / b.speed;
  } else if (team.phase == Team::Phase::kMoving && team.agent != kNone) {
    const Bot& a = bots_[team.agent];
    const bool moving = ctl_.Next(team.agent) != kNoPoint;
    start = moving ? ctl_.Next(team.agent) : ctl_.At(team.agent);
    ready += (moving ? (a.len - a.s) / a.speed + (a.turn_len - a.turn_s) : 0.0) + a.dwell;
  } else if (team.phase == Team::Phase::kLeaving) {
    start = team.leave_at;
  } else {
    start = team.task.picks.front();
  }
}

bool StreamSim::MemberRemaining(const Task& task, PlanTask& out) const {
  const Team& team = teams_[static_cast<std::size_t>(task.team)];
  if (team.phase == Team::Phase::kGathering) return Remaining(task, 0, out);
  if (team.phase != Team::Phase::kMoving || team.agent == kNone) return false;
  const Bot& a = bots_[team.agent];
  if (a.tasks.empty()) return false;
  return Remaining(a.tasks.front(), a.tasks.front().next_stop + (a.dwell > 0 ? 1 : 0), out);
}

double StreamSim::TeamHeading(const Bot& a) const {
  if (!a.moving || a.turn_len <= 0 || a.turn_s >= a.turn_len) return a.heading;
  const double turn = std::remainder(a.heading - a.turn_from, 2.0 * std::numbers::pi);
  return a.turn_from + turn * (a.turn_s / a.turn_len);
}

Eigen::Vector2d StreamSim::SlotPosition(const Team& team, int member) const {
  const auto i = static_cast<std::size_t>(std::max(0, member));
  if (team.agent == kNone) {
    const PointId p = team.leave_at != kNoPoint ? team.leave_at : team.task.picks.front();
    return map_->point(p).position + FormationOffsets(team.heading0)[i];
  }
  return Position(team.agent) + FormationOffsets(TeamHeading(bots_[team.agent]))[i];
}

bool StreamSim::PlaceAgent(std::size_t ti, PointId p, double t) {
  Team& team = teams_[ti];
  std::size_t a = kNone;
  if (!agent_pool_.empty()) {
    a = agent_pool_.back();
    ctl_.SetGroup(a, team.group);
    if (!ctl_.Place(a, p).ok()) return false;
    agent_pool_.pop_back();
  } else {
    if (bots_.size() == bots_.capacity()) return false;  // never: at most one agent per robot
    auto added = ctl_.AddRobot("formation-agent-" + std::to_string(bots_.size()), p, team.group);
    if (!added.ok()) return false;
    a = *added;
    bots_.emplace_back();
    // AddRobot checked the point without the envelope: place it again with it.
    ctl_.SetEnvelope(a, radius_);
    ctl_.Remove(a);
    if (!ctl_.Place(a, p).ok()) {
      bots_[a].agent = true;
      bots_[a].removed = true;
      agent_pool_.push_back(a);
      return false;
    }
  }
  Bot& agent = bots_[a];
  agent = Bot{};
  agent.id = "formation " + out_.orders[team.order].order_id;
  agent.agent = true;
  agent.team = static_cast<int>(ti);
  agent.heading = team.heading0;
  agent.tasks.push_back(team.task);
  ctl_.SetEnvelope(a, radius_);
  ctl_.SetIdle(a, false);
  ctl_.SetWorking(a, true, t + 1e9);  // assembling: never asked to yield
  team.agent = a;
  return true;
}

void StreamSim::PoolAgent(Team& team) {
  if (team.agent == kNone) return;
  const std::size_t a = team.agent;
  if (!ctl_.removed(a)) ctl_.Remove(a);
  Bot& agent = bots_[a];
  agent.removed = true;
  agent.moving = false;
  agent.tasks.clear();
  agent_pool_.push_back(a);
  team.agent = kNone;
}

bool StreamSim::Join(std::size_t r, double t) {
  Bot& b = bots_[r];
  const Task& task = b.tasks.front();
  const auto ti = static_cast<std::size_t>(task.team);
  Team& team = teams_[ti];
  if (team.phase != Team::Phase::kGathering || HoldsForRendezvous(b, t)) return false;
  const PointId p = task.picks.front();
  const PointId at = ctl_.At(r);
  if (team.agent == kNone) {
    if (at != p) return false;  // the first member drives onto P under the controller
    ctl_.Remove(r);
    if (!PlaceAgent(ti, p, t)) {  // a robot within the envelope: wait
      (void)ctl_.Place(r, p);
      ctl_.SetIdle(r, false);
      return false;
    }
  } else if (at == p) {
    ctl_.Remove(r);
  } else {
    const std::vector<PointId> route = ctl_.RemainingRoute(r);
    if (route.size() != 2 || route.back() != p) return false;
    (void)ctl_.SetRoute(r, {at});  // withdraws its requests; it keeps its point until clear
    ctl_.WaitOn(r, -1, t, {});     // and it waits on nobody any more
  }
  b.join_wait = 0;
  b.slot = Slot::kToSlot;
  b.member = task.member;
  // Along its arc towards P as far as D_f short of it, then into the slot: near the point it
  // leaves it drives where any robot would (others keep eps1 from that point), and the rest
  // lies within the agent's envelope.
  b.from = map_->point(at).position;
  b.to = SlotPosition(team, b.member);
  const Eigen::Vector2d along = map_->point(p).position - b.from;
  b.via_s = std::max(0.0, along.norm() - radius_);
  b.via = b.via_s > 0 ? Eigen::Vector2d(b.from + along * (b.via_s / along.norm())) : b.from;
  b.s = 0;
  b.len = b.via_s + (b.to - b.via).norm();
  b.speed = config_.allocation.speed;
  b.moving = b.waiting = false;
  return true;
}

bool StreamSim::HoldsForRendezvous(const Bot& b, double t) const {
  const Team& team = teams_[static_cast<std::size_t>(b.tasks.front().team)];
  if (team.phase != Team::Phase::kGathering) return false;
  const auto i = static_cast<std::size_t>(b.tasks.front().member);
  return !team.called || t + kTiny < team.depart[i];
}

void StreamSim::CallRendezvous(Team& team, double t) {
  const PointId p = team.task.picks.front();
  std::vector<double> eta;
  for (std::size_t m : team.members) {
    const Bot& b = bots_[m];
    if (b.removed || b.tasks.empty() || b.tasks.front().team != team.task.team || b.slot != Slot::kNone) return;
    const bool moving = ctl_.Next(m) != kNoPoint;
    const double cost = routes_->Cost(moving ? ctl_.Next(m) : ctl_.At(m), p);
    eta.push_back((std::isfinite(cost) ? cost : 0.0) + (moving ? (b.len - b.s) / b.speed : 0.0));
  }
  const double last = *std::max_element(eta.begin(), eta.end());
  team.depart.clear();
  for (double e : eta) team.depart.push_back(t + (last - e));
  team.called = true;
}

void StreamSim::AwaitMembers(std::size_t ti, double t) {
  const Team& team = teams_[ti];
  int awaited = -1;
  for (std::size_t m : team.members) {
    if (bots_[m].slot != Slot::kNone || bots_[m].team != static_cast<int>(ti)) continue;
    // A member held up by a robot that itself waits for the team's point: that cycle is a
    // deadlock the controller resolves once it sees the agent wait for the member.
    int v = ctl_.WaitsOn(m);
    for (std::size_t hops = 0; v >= 0 && hops < bots_.size(); ++hops) {
      if (static_cast<std::size_t>(v) == team.agent) {
        awaited = static_cast<int>(m);
        break;
      }
      v = ctl_.WaitsOn(static_cast<std::size_t>(v));
    }
    if (awaited >= 0) break;
  }
  ctl_.WaitOn(team.agent, awaited, t, "formation " + out_.orders[team.order].order_id + ": waiting for " +
                                        (awaited >= 0 ? bots_[static_cast<std::size_t>(awaited)].id : "-"));
}

bool StreamSim::NudgeIdle(std::size_t r, double t, const std::vector<PointId>& keep_clear) {
  const Bot& b = bots_[r];
  if (b.agent || b.removed || b.slot != Slot::kNone || b.moving || b.dwell > 0 || ctl_.HasRoute(r)) return false;
  const bool idle = b.tasks.empty() || (b.tasks.front().team >= 0 && HoldsForRendezvous(b, t));
  return idle && ctl_.StepAside(r, keep_clear);
}

void StreamSim::WaitToJoin(std::size_t r, double budget) {
  Bot& b = bots_[r];
  out_.total_waiting_time += budget;
  b.join_wait += budget;
  if (b.join_wait < config_.traffic.blocked_after) return;
  const Task& task = b.tasks.front();
  const std::string& order = out_.orders[task.order].order_id;
  const std::string why = b.id + ": formation " + order + ": its rendezvous point '" +
                          map_->point(task.picks.front()).name + "' stayed too close to others";
  out_.blocked.push_back(why);
  Fail(task.order, "blocked: " + why);  // StepTeams breaks the team up
  b.join_wait = 0;
}

void StreamSim::MoveMember(std::size_t r) {
  Bot& b = bots_[r];
  if (b.slot == Slot::kInSlot) return;
  const double d = std::min(config_.time_step * b.speed, b.len - b.s);
  b.s += std::max(0.0, d);
  out_.total_distance += std::max(0.0, d);
  const bool arrived = b.s >= b.len - kTiny;
  if (b.slot == Slot::kToSlot) {
    // It keeps the point it joined from until clear of it; then the agent stands for it.
    if (!ctl_.removed(r) && (arrived || b.s >= clearance_)) ctl_.Remove(r);
    if (arrived) b.slot = Slot::kInSlot;
    return;
  }
  if (!arrived) return;
  // Out of its slot, at the point it was placed at: on its own again.
  b.slot = Slot::kNone;
  ctl_.SetEnvelope(r, 0.0);
  KeepFormer(b, b.team);
  SyncGroup(r);
  ctl_.SetIdle(r, b.tasks.empty());
}

void StreamSim::TeamDropDone(std::size_t a, double t) {
  Bot& agent = bots_[a];
  const auto ti = static_cast<std::size_t>(agent.team);
  Team& team = teams_[ti];
  Complete(team.order, t);
  team.phase = Team::Phase::kLeaving;
  team.leave_at = agent.tasks.front().drop;
  agent.tasks.clear();
  ctl_.SetLoaded(a, false);
  ctl_.SetIdle(a, false);
  ctl_.SetWorking(a, true, t + 1e9);  // holds D for the members until the last one leaves
  for (std::size_t m : team.members) {
    Bot& b = bots_[m];
    if (!b.tasks.empty() && b.tasks.front().team == static_cast<int>(ti)) b.tasks.pop_front();
  }
}

void StreamSim::StepTeams(double t) {
  for (std::size_t ti : active_teams_) {
    Team& team = teams_[ti];
    switch (team.phase) {
      case Team::Phase::kGathering: {
        if (terminal_of_[team.order]) {
          BreakTeam(ti, {});
          break;
        }
        if (!team.called) CallRendezvous(team, t);
        if (team.agent != kNone) AwaitMembers(ti, t);
        bool all = true;
        for (std::size_t m : team.members) {
          all = all && bots_[m].slot == Slot::kInSlot && bots_[m].team == static_cast<int>(ti);
        }
        if (all) {
          team.phase = Team::Phase::kMoving;
          ctl_.WaitOn(team.agent, -1, t, {});
          ctl_.SetWorking(team.agent, false);
        }
        break;
      }
      case Team::Phase::kMoving:
        break;
      case Team::Phase::kLeaving:
        if (StepLeaving(ti, t)) team.phase = Team::Phase::kDone;
        break;
      case Team::Phase::kDone:
        break;
    }
    if (team.phase == Team::Phase::kDone && !team.apart) CheckApart(ti);
  }
  std::erase_if(active_teams_, [&](std::size_t ti) { return teams_[ti].apart; });
}

void StreamSim::BreakTeam(std::size_t ti, const std::string& why) {
  Team& team = teams_[ti];
  if (!why.empty()) Fail(team.order, why);
  bool joined = false;
  for (std::size_t m : team.members) {
    Bot& b = bots_[m];
    std::erase_if(b.tasks, [&](const Task& task) { return task.team == static_cast<int>(ti); });
    if (b.slot != Slot::kNone && b.team == static_cast<int>(ti)) {
      joined = true;  // leaves P as it would leave a drop
    } else if (!b.removed) {
      if (b.team == static_cast<int>(ti)) KeepFormer(b, b.team);  // it was approaching: near its mates
      SyncGroup(m);
      ctl_.SetIdle(m, b.tasks.empty());
    }
  }
  team.leave_at = team.task.picks.front();
  team.phase = joined ? Team::Phase::kLeaving : Team::Phase::kDone;
  if (!joined) PoolAgent(team);
}

void StreamSim::DissolveBlocked(std::size_t a) {
  Bot& agent = bots_[a];
  const auto ti = static_cast<std::size_t>(agent.team);
  Team& team = teams_[ti];
  (void)ctl_.SetRoute(a, {ctl_.At(a)});  // withdraws its grant requests; it keeps its point
  ctl_.WaitOn(a, -1, 0.0, {});
  ctl_.SetWorking(a, true, 1e18);
  agent.waiting = false;
  team.phase = Team::Phase::kLeaving;
  team.leave_at = ctl_.At(a);
  for (std::size_t m : team.members) {
    Bot& b = bots_[m];
    if (!b.tasks.empty() && b.tasks.front().team == static_cast<int>(ti)) b.tasks.pop_front();
  }
}

// A free point for member m next to the drop point D: the first point of its onward route,
// else a neighbour of D (sidings first). None free: the robot holding one is asked to move
// (an idle one is nudged; for one that waits for D itself the agent's wait closes the cycle
// the controller breaks), and kNoPoint.
PointId StreamSim::PlaceOff(std::size_t ti, std::size_t m, double t) {
  Team& team = teams_[ti];
  const PointId d = team.leave_at;
  const Bot& b = bots_[m];
  std::vector<PointId> candidates;
  if (!b.tasks.empty() && b.tasks.front().Stop() != d) {
    auto path = routes_->Path(d, b.tasks.front().Stop());
    if (path.ok() && path->points.size() >= 2) candidates.push_back(path->points[1]);
  }
  for (int pass = 0; pass < 2; ++pass) {
    for (ArcId arc : map_->out_arcs(d)) {
      const PointId q = map_->arc(arc).to;
      const bool siding = !IsServicePoint(map_->point(q).kind) && map_->IntersectionOf(q) < 0;
      if (siding == (pass == 0)) candidates.push_back(q);
    }
  }
  for (PointId q : candidates) {
    if (ctl_.Place(m, q).ok()) {
      ctl_.WaitOn(team.agent, -1, t, {});
      return q;
    }
  }
  for (PointId q : candidates) {
    const int h = ctl_.HolderOf(q);
    if (h < 0) continue;  // only points near it are held: those robots drive on
    if (!NudgeIdle(static_cast<std::size_t>(h), t, {d, q})) {
      ctl_.WaitOn(team.agent, h, t, "formation " + out_.orders[team.order].order_id + ": a member leaves '" +
                                        map_->point(d).name + "' for '" + map_->point(q).name + "'");
    }
    break;
  }
  return kNoPoint;
}

// True when every member is back on its own (the agent pooled).
bool StreamSim::StepLeaving(std::size_t ti, double t) {
  Team& team = teams_[ti];
  const PointId d = team.leave_at;
  std::vector<std::size_t> pending;
  bool out = false;
  for (std::size_t m : team.members) {
    const Bot& b = bots_[m];
    if (b.team != static_cast<int>(ti) || b.removed) continue;
    if (b.slot == Slot::kToSlot) return false;  // broken up while it drove in: let it arrive
    if (b.slot == Slot::kInSlot) pending.push_back(m);
    if (b.slot == Slot::kOut) out = true;
  }
  if (pending.empty()) {
    if (out) return false;
    PoolAgent(team);
    return true;
  }
  // Members with work ahead leave first (an idle one may stay on D).
  std::stable_sort(pending.begin(), pending.end(), [&](std::size_t a, std::size_t b) {
    return !bots_[a].tasks.empty() && bots_[b].tasks.empty();
  });
  auto start_out = [&](std::size_t m, const Eigen::Vector2d& from, PointId target) {
    Bot& b = bots_[m];
    b.slot = Slot::kOut;
    b.from = from;
    b.to = map_->point(target).position;
    b.via_s = 0;
    b.s = 0;
    b.len = (b.to - b.from).norm();
    b.speed = config_.allocation.speed;
    ctl_.SetIdle(m, b.tasks.empty());
    out = true;
  };
  bool placed = false;
  for (std::size_t k = 0; k < pending.size(); ++k) {
    const std::size_t m = pending[k];
    // Until it has driven out of its slot it keeps the formation's envelope (D_f off its point).
    ctl_.SetEnvelope(m, radius_);
    const Eigen::Vector2d from = Position(m);
    if (k + 1 < pending.size()) {  // placed beside D while the agent still holds D
      const PointId target = PlaceOff(ti, m, t);
      if (target == kNoPoint) break;  // retried next step
      start_out(m, from, target);
      placed = true;
      continue;
    }
    if (out) break;  // the last one takes D once the others are at their points
    const std::size_t a = team.agent;
    if (a == kNone) break;  // never: a member in its slot has its agent
    ctl_.Remove(a);
    if (!ctl_.Place(m, d).ok()) {
      (void)ctl_.Place(a, d);
      ctl_.SetIdle(a, false);
      ctl_.SetWorking(a, true, 1e18);
      break;
    }
    PoolAgent(team);
    start_out(m, from, d);
    placed = true;
  }
  // No member placed and none driving out for blocked_after: those still in their slots leave
  // the floor as faulted (no room to leave), so no later order of theirs waits forever.
  team.leave_wait = placed || out ? 0.0 : team.leave_wait + config_.time_step;
  if (team.leave_wait < config_.traffic.blocked_after) return false;
  const std::string why = "formation " + out_.orders[team.order].order_id + ": no room to leave '" +
                          map_->point(d).name + "' for " + std::to_string(config_.traffic.blocked_after) + " s";
  out_.blocked.push_back(why);
  for (std::size_t m : pending) {
    Bot& b = bots_[m];
    if (b.slot != Slot::kInSlot) continue;
    FailTasks(m, "blocked: " + b.id + ": " + why);
    if (!ctl_.removed(m)) ctl_.Remove(m);
    b.removed = true;
    b.slot = Slot::kNone;
    b.team = b.former = -1;
  }
  PoolAgent(team);
  return true;
}

void StreamSim::CheckApart(std::size_t ti) {
  Team& team = teams_[ti];
  const int me = static_cast<int>(ti);
  bool all = true;
  for (std::size_t m : team.members) {
    Bot& b = bots_[m];
    if (b.removed || b.former != me) continue;
    bool apart = true;
    for (std::size_t o : team.members) {
      const Bot& c = bots_[o];
      if (o == m || c.removed || (c.former != me && c.team != me)) continue;
      apart = apart && (Position(m) - Position(o)).norm() >= clearance_ - 1e-9;
    }
    if (apart) {
      b.former = -1;
      SyncGroup(m);
    } else {
      all = false;
    }
  }
  team.apart = all;
}

}  // namespace dispatch::engine::stream_sim
