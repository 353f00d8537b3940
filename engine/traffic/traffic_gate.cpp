// TrafficGate: creation, the plan helpers and effects shared by solo agents and teams, and the
// public interface. Solo agents are in traffic_gate_solo.cpp, formations (team agents) in
// traffic_gate_teams.cpp, the shared state in traffic_gate_impl.h.
#include "engine/traffic/traffic_gate.h"

#include <algorithm>
#include <cmath>
#include <tuple>
#include <unordered_map>
#include <utility>

#include "engine/fleet/formation.h"
#include "engine/traffic/traffic_gate_impl.h"

namespace dispatch::engine {

TrafficGate::TrafficGate(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
TrafficGate::~TrafficGate() = default;

Result<std::unique_ptr<TrafficGate>> TrafficGate::Create(
    std::shared_ptr<const WarehouseMap> map, std::shared_ptr<const RouteTable> routes,
    TrafficControllerConfig config) {
  auto ctl = TrafficController::Create(map, config);
  if (!ctl.ok()) return ctl.error();
  auto impl = std::make_unique<Impl>(std::move(map), std::move(routes), config, std::move(ctl).value());
  return std::unique_ptr<TrafficGate>(new TrafficGate(std::move(impl)));
}

// --- Impl: plan helpers ------------------------------------------------------------------

GateImpl::GateImpl(std::shared_ptr<const WarehouseMap> m,
                   std::shared_ptr<const RouteTable> r, TrafficControllerConfig c,
                   TrafficController controller)
    : map(std::move(m)), routes(std::move(r)), config(c), ctl(std::move(controller)) {
  ctl.SetRouteBound(routes);  // bounded detour searches skip what cannot arrive in time
  // Service points by 1 m cell, then every point against the service points around it.
  const double reach = config.point_clearance + FormationRadius();
  auto cell = [&](const Eigen::Vector2d& p) {
    return std::pair<long, long>{static_cast<long>(std::floor(p.x() / std::max(reach, 1e-3))),
                                 static_cast<long>(std::floor(p.y() / std::max(reach, 1e-3)))};
  };
  std::map<std::pair<long, long>, std::vector<PointId>> service;
  for (std::size_t i = 0; i < map->point_count(); ++i) {
    const Point& p = map->point(static_cast<PointId>(i));
    if (IsServicePoint(p.kind) && p.kind != PointKind::kPark) {
      service[cell(p.position)].push_back(static_cast<PointId>(i));
    }
  }
  blocks_service.assign(map->point_count(), false);
  for (std::size_t i = 0; i < map->point_count(); ++i) {
    const Eigen::Vector2d& xy = map->point(static_cast<PointId>(i)).position;
    const auto [cx, cy] = cell(xy);
    for (long dx = -1; dx <= 1 && !blocks_service[i]; ++dx) {
      for (long dy = -1; dy <= 1 && !blocks_service[i]; ++dy) {
        auto it = service.find({cx + dx, cy + dy});
        if (it == service.end()) continue;
        for (PointId q : it->second) {
          if ((map->point(q).position - xy).norm() < reach) blocks_service[i] = true;
        }
      }
    }
  }
}

long GateImpl::IndexOf(const GateBot& b, std::uint64_t seq) {
  const std::size_t i = FindSequence(b.plan.waypoints, seq);
  return i == static_cast<std::size_t>(-1) ? -1 : static_cast<long>(i);
}

long GateImpl::RunEnd(const GateBot& b, long from, PointId p, long limit) {
  const auto& w = b.plan.waypoints;
  long j = from;
  if (j < 0 || j > limit || j >= static_cast<long>(w.size()) || w[static_cast<std::size_t>(j)].point != p) {
    return from - 1;
  }
  while (j + 1 < static_cast<long>(w.size()) && j + 1 <= limit && w[static_cast<std::size_t>(j + 1)].point == p) ++j;
  return j;
}

long GateImpl::GrantedRunEnd(const GateBot& b, PointId at, PointId next) {
  // A robot nudged before it ever had a plan gets one whose anchor (where it stands) it has
  // not reported: released from the run at `next` on only, it stood granted and unreleased for
  // ever, holding its corridor (found on the Wang2019 grid: an idle robot nudged into the
  // drop corridor of a corner blocked every robot bound for that drop).
  const long last = static_cast<long>(b.plan.waypoints.size()) - 1;
  return RunEnd(b, RunEnd(b, b.idx + 1, at, last) + 1, next, last);
}

double GateImpl::Departure(const GateBot& b, long i) const {
  if (i < 0) return 0.0;
  const Waypoint& w = b.plan.waypoints[static_cast<std::size_t>(i)];
  // Claiming its next point early, it asks once its work there is done (the robot still leaves
  // at its planned departure).
  if (config.execution != PlanExecution::kTimes && i == b.idx) return b.reach_time + w.dwell;
  double t = w.departure();
  if (i == b.idx) t = std::max(t, b.reach_time + w.dwell);
  return t;
}

void GateImpl::Release(GateBot& b, long upto, int intersection, std::vector<GateEffect>& out) {
  if (upto < 0 || upto >= static_cast<long>(b.plan.waypoints.size())) return;
  const auto seq = static_cast<std::uint64_t>(b.plan.waypoints[static_cast<std::size_t>(upto)].seq);
  if (seq <= b.released) return;
  b.released = seq;
  SendRelease(b, intersection, out);
}

void GateImpl::SendRelease(GateBot& b, int intersection, std::vector<GateEffect>& out) {
  GateEffect e;
  e.kind = GateEffect::Kind::kRelease;
  e.robot = b.id;
  e.release_up_to = b.released;
  e.intersection = intersection;
  e.resume = b.held;
  b.held = false;
  out.push_back(std::move(e));
}

void GateImpl::Hold(GateBot& b, const std::string& why, std::vector<GateEffect>& out) {
  if (b.held) return;
  b.held = true;
  b.hold_reason = why;
  GateEffect e;
  e.kind = GateEffect::Kind::kHold;
  e.robot = b.id;
  e.hold_at = b.released;
  e.reason = why;
  out.push_back(std::move(e));
}

void GateImpl::HoldPaused(GateBot& b, std::vector<GateEffect>& out) {
  const std::string why = "paused by " + b.paused_by;
  if (b.held && b.hold_reason != why) b.held = false;  // the Hold again, with the pause as reason
  Hold(b, why, out);
}

std::optional<GateImpl::TeamSpan> GateImpl::SpanOf(const GateBot& b, const std::string& o) {
  auto cached = b.spans.find(o);
  return cached != b.spans.end() ? cached->second : FindSpan(b, o);
}

// The formation segment of order `o` in b's plan: join index J (first waypoint of the run at
// the rendezvous point before the slot), F (the formation's first pick), E (its drop).
std::optional<GateImpl::TeamSpan> GateImpl::FindSpan(const GateBot& b, const std::string& o) {
  const auto& w = b.plan.waypoints;
  long first = -1, f = -1, e = -1;
  for (long i = 0; i < static_cast<long>(w.size()); ++i) {
    if (b.plan.order_of[static_cast<std::size_t>(i)] != o) continue;
    if (first < 0) first = i;
    if (f < 0 && w[static_cast<std::size_t>(i)].action == WaypointAction::kPick) f = i;
    e = i;
  }
  if (f < 0 || e < f) return std::nullopt;
  long j = f;
  const PointId p = w[static_cast<std::size_t>(f)].point;
  while (j - 1 >= first && w[static_cast<std::size_t>(j - 1)].point == p) --j;
  TeamSpan s;
  s.join = j;
  s.first_pick = f;
  s.drop = e;
  s.rendezvous = p;
  s.seq_first_pick = static_cast<std::uint64_t>(w[static_cast<std::size_t>(f)].seq);
  s.seq_drop = static_cast<std::uint64_t>(w[static_cast<std::size_t>(e)].seq);
  return s;
}

// The next formation join boundary after index `from` (the J of the first team order ahead),
// or -1.
long GateImpl::NextJoin(const GateBot& b, long from, std::string* order) const {
  if (b.plan.teams.empty()) return -1;  // no formation order in the plan
  const auto& ow = b.plan.order_of;
  std::string seen;
  for (long i = std::max(0L, from + 1); i < static_cast<long>(ow.size()); ++i) {
    const std::string& o = ow[static_cast<std::size_t>(i)];
    if (o.empty() || o == seen || !b.plan.teams.count(o)) continue;
    seen = o;
    auto span = SpanOf(b, o);
    if (span && span->join > from) {
      if (order) *order = o;
      return span->join;
    }
  }
  return -1;
}

int GateImpl::GroupOf(const std::string& order) {
  // A hash, so that teammates agree on it without bookkeeping (a collision only relaxes
  // clearance between two formations' members, never within one robot).
  return static_cast<int>(std::hash<std::string>{}(order) & 0x3fffffff) | 1;
}

bool GateImpl::IsStop(const Waypoint& w) {
  return w.action != WaypointAction::kMove || w.dwell > 0.0;
}

// --- Public interface ----------------------------------------------------------------------

void TrafficGate::Connect(const std::string& robot, const Eigen::Vector2d& xy, PointId point) {
  Impl& s = *impl_;
  GateBot& b = s.Get(robot);
  b.id = robot;
  b.connected = true;
  b.removed = false;
  b.synced = false;
  b.resume_pending = true;  // it may still hold on a Hold from before the stream broke
  b.held = false;
  const PointKind kind = s.map->point(point).kind;
  if (b.home == kNoPoint && (kind == PointKind::kPark || kind == PointKind::kCharge)) {
    b.home = point;
  }
  b.xy = xy;
  b.has_xy = true;
  if (b.team.empty() && s.OnFloor(b)) {
    const auto r = static_cast<std::size_t>(b.ctl);
    const PointId at = s.ctl.At(r), next = s.ctl.Next(r);
    if (point != at && point != next) {  // it is elsewhere now: re-place it there
      s.ctl.Remove(r);
      b.leg_stale = true;
    }
  }
  if (b.team.empty() && !s.OnFloor(b)) {
    if (!s.PlaceBot(b, point)) s.PlaceNear(b);
  }
  b.leg_stale = true;
}

void TrafficGate::Disconnect(const std::string& robot) {
  if (GateBot* bot = impl_->Find(robot)) bot->connected = false;
}

void TrafficGate::SetPlan(const std::string& robot, GatePlan plan) {
  Impl& s = *impl_;
  GateBot& b = s.Get(robot);
  b.id = robot;
  if (plan.order_of.size() != plan.waypoints.size()) plan.order_of.resize(plan.waypoints.size());
  plan.next_sequence = std::max(plan.next_sequence, b.plan.next_sequence);
  b.plan = std::move(plan);
  s.Reindex(b);
  if (b.ctl >= 0) s.ctl.SetRank(static_cast<std::size_t>(b.ctl), b.plan.release);
  b.leg_stale = true;
  if (b.released < b.reached_seq) b.released = b.reached_seq;
  s.SyncTeams(b);
}

bool TrafficGate::SetPaused(const std::string& robot, const std::string& by) {
  if (robot.empty()) return false;
  GateBot& b = impl_->Get(robot);
  b.id = robot;
  b.paused_by = by;
  return true;
}

bool TrafficGate::Remove(const std::string& robot) {
  Impl& s = *impl_;
  GateBot* b = s.Find(robot);
  if (!b || b->connected || !b->team.empty()) return false;
  if (s.OnFloor(*b)) s.ctl.Remove(static_cast<std::size_t>(b->ctl));
  s.strays.erase(robot);
  b->removed = true;
  b->leg_stale = true;
  b->held = false;
  return true;
}

void TrafficGate::Unblock(const std::string& robot, double t) {
  GateBot* b = impl_->Find(robot);
  if (!b) return;
  b->blocked = false;
  if (b->team.empty() && impl_->OnFloor(*b)) impl_->ctl.RestartWaitClock(static_cast<std::size_t>(b->ctl), t);
}

void TrafficGate::Reached(const std::string& robot, std::uint64_t sequence, double t,
                          const std::optional<Eigen::Vector2d>& xy) {
  if (GateBot* bot = impl_->Find(robot)) Reached(*bot, sequence, t, xy);
}

void TrafficGate::Reached(GateBot& bot, std::uint64_t sequence, double t, const std::optional<Eigen::Vector2d>& xy) {
  if (xy) {
    bot.xy = *xy;
    bot.has_xy = true;
  }
  impl_->OnReached(bot, sequence, t);
}

void TrafficGate::Report(const std::string& robot, const Eigen::Vector2d& xy, std::uint64_t last_waypoint,
                         double t) {
  if (GateBot* bot = impl_->Find(robot)) Report(*bot, xy, last_waypoint, t);
}

void TrafficGate::Report(GateBot& bot, const Eigen::Vector2d& xy, std::uint64_t last_waypoint, double t) {
  bot.xy = xy;
  bot.has_xy = true;
  if (last_waypoint > bot.reached_seq) impl_->OnReached(bot, last_waypoint, t);
  bot.synced = true;
}

GateBot* TrafficGate::Entry(const std::string& robot) { return impl_->Find(robot); }

std::vector<GateEffect> TrafficGate::Step(double t) {
  Impl& s = *impl_;
  std::vector<GateEffect> out;
  s.next_wake = std::numeric_limits<double>::infinity();
  // A reconnected robot may still obey a Hold whose Resume was lost with its old stream: it
  // gets a Resume with its horizon (the horizon, not the Hold, is what keeps it safe), and a
  // Hold again if it must still wait.
  for (GateBot* bot : s.in_order) {
    GateBot& b = *bot;
    if (!b.resume_pending || !b.connected) continue;
    b.resume_pending = false;
    b.held = true;  // sent as a Resume
    s.SendRelease(b, -1, out);
  }
  s.PlaceStrays();
  s.StepTeams(t, out);
  for (GateBot* b : s.in_order) s.StepSolo(*b, t, out);
  // Deadlock breaking and nudges re-route standing robots: their legs follow.
  s.ctl.ResolveDeadlocks(t);
  for (GateBot* bot : s.in_order) {
    GateBot& b = *bot;
    if (!b.team.empty() || !s.OnFloor(b) || !b.connected || b.leg_stale) continue;
    const auto r = static_cast<std::size_t>(b.ctl);
    if (s.ctl.Next(r) == kNoPoint && !s.LegIsRemainingRoute(b)) s.AdoptRoute(b, t, out);
  }
  s.StepTeamsAfterDeadlocks(t, out);
  return out;
}

void TrafficGate::SampleDistances(double t) { impl_->SampleDistances(t); }

double TrafficGate::NextWake() const { return impl_->next_wake; }

std::uint64_t TrafficGate::LeavingEnded() const { return impl_->leaving_ended; }

bool TrafficGate::Paused(const std::string& robot) const {
  const GateBot* bot = impl_->Find(robot);
  return bot && !bot->paused_by.empty();
}

bool TrafficGate::Available(const std::string& robot) const {
  const GateBot* bot = impl_->Find(robot);
  return !bot || bot->team.empty() || impl_->teams.count(bot->team) == 0 ||
         impl_->teams.at(bot->team).phase != GateTeam::Phase::kLeaving;
}

PointId TrafficGate::StartPoint(const std::string& robot) const {
  const Impl& s = *impl_;
  const GateBot* bot = s.Find(robot);
  if (!bot || !bot->team.empty() || !s.OnFloor(*bot)) return kNoPoint;
  const auto r = static_cast<std::size_t>(bot->ctl);
  return s.ctl.Next(r) != kNoPoint ? s.ctl.Next(r) : s.ctl.At(r);
}

std::uint64_t TrafficGate::ReleasedUpTo(const std::string& robot) const {
  const GateBot* bot = impl_->Find(robot);
  return bot ? bot->released : 0;
}

std::uint64_t TrafficGate::ReleasedUpTo(const GateBot& robot) const { return robot.released; }

std::string TrafficGate::Describe(const std::string& robot) const {
  const Impl& s = *impl_;
  auto it = s.bots.find(robot);
  if (it == s.bots.end()) return robot + ": unknown";
  const GateBot& b = it->second;
  std::string out;
  if (!b.team.empty()) {
    out = robot + " in formation " + b.team;
    auto t = s.teams.find(b.team);
    if (t != s.teams.end() && t->second.ctl >= 0) out += ": " + s.ctl.Describe(static_cast<std::size_t>(t->second.ctl));
  } else if (s.OnFloor(b)) {
    out = s.ctl.Describe(static_cast<std::size_t>(b.ctl));
  } else {
    out = robot + " (not on the floor)";
  }
  const GateTeamKeys keys = s.TeamKeys(b);
  if (!keys[0].empty()) {
    out += "; team keys " + keys[0];
    for (std::size_t k = 1; k < keys.size() && !keys[k].empty(); ++k) out += "/" + keys[k];
  }
  out += "; waypoint " + std::to_string(b.idx) + "/" + std::to_string(b.plan.waypoints.size()) +
         ", released " + std::to_string(b.released) + (b.connected ? "" : ", offline");
  return out;
}

std::vector<GateIntersection> TrafficGate::Intersections() const {
  const Impl& s = *impl_;
  std::unordered_map<std::string, const GateTeam*> team_of_agent;
  for (const auto& [order, team] : s.teams) {
    if (team.ctl >= 0) team_of_agent[s.ctl.robot_id(static_cast<std::size_t>(team.ctl))] = &team;
  }
  auto robots_of = [&](const std::vector<std::string>& agents) {
    std::vector<std::string> out;
    for (const auto& agent : agents) {
      auto t = team_of_agent.find(agent);
      if (t == team_of_agent.end()) {
        out.push_back(agent);
      } else {
        out.insert(out.end(), t->second->members.begin(), t->second->members.end());
      }
    }
    return out;
  };
  const IntersectionGrants& grants = s.ctl.grants();
  std::vector<GateIntersection> out(grants.guard_count());
  for (std::size_t g = 0; g < out.size(); ++g) {
    out[g].holders = robots_of(grants.Holders(g));
    out[g].waiting = robots_of(grants.Queue(g));
  }
  return out;
}

GateRobotState TrafficGate::RobotState(const std::string& robot) const {
  GateRobotState state;
  const GateBot* bot = impl_->Find(robot);
  if (!bot) return state;
  state.held = bot->held;
  if (state.held) state.reason = bot->hold_reason;
  state.paused_by = bot->paused_by;
  state.formation = bot->team;
  state.moved_by_team = !bot->team.empty() && !impl_->OnFloor(*bot);
  state.teams = impl_->TeamKeys(*bot);
  return state;
}

const MinDistance& TrafficGate::min_distance() const { return impl_->min_distance; }

std::vector<std::string> TrafficGate::TakeNotes() { return std::exchange(impl_->notes, {}); }
const TrafficStats& TrafficGate::stats() const { return impl_->ctl.stats(); }

}  // namespace dispatch::engine
