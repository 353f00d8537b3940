// TrafficGate: robots and their legs (solo agents), releases, rewrites, minimum distance.
// Formations (team agents) are in traffic_gate_teams.cpp; the shared state in
// traffic_gate_impl.h.
#include "server/traffic_gate.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "engine/fleet/formation.h"
#include "server/traffic_gate_impl.h"

namespace dispatch::server {

using engine::PointId;
using engine::TrafficDecision;
using engine::WaypointAction;

TrafficGate::TrafficGate(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
TrafficGate::~TrafficGate() = default;

engine::Result<std::unique_ptr<TrafficGate>> TrafficGate::Create(
    std::shared_ptr<const engine::WarehouseMap> map, std::shared_ptr<const engine::RouteTable> routes,
    engine::TrafficControllerConfig config) {
  auto ctl = engine::TrafficController::Create(map, config);
  if (!ctl.ok()) return ctl.error();
  auto impl = std::make_unique<Impl>(std::move(map), std::move(routes), config, std::move(ctl).value());
  return std::unique_ptr<TrafficGate>(new TrafficGate(std::move(impl)));
}

// --- Impl: plan helpers ------------------------------------------------------------------

GateImpl::GateImpl(std::shared_ptr<const engine::WarehouseMap> m,
                   std::shared_ptr<const engine::RouteTable> r, engine::TrafficControllerConfig c,
                   engine::TrafficController controller)
    : map(std::move(m)), routes(std::move(r)), config(c), ctl(std::move(controller)) {
  // Service points by 1 m cell, then every point against the service points around it.
  const double reach = config.point_clearance + engine::FormationRadius();
  auto cell = [&](const Eigen::Vector2d& p) {
    return std::pair<long, long>{static_cast<long>(std::floor(p.x() / std::max(reach, 1e-3))),
                                 static_cast<long>(std::floor(p.y() / std::max(reach, 1e-3)))};
  };
  std::map<std::pair<long, long>, std::vector<PointId>> service;
  for (std::size_t i = 0; i < map->point_count(); ++i) {
    const engine::Point& p = map->point(static_cast<PointId>(i));
    if (IsServicePoint(p.kind) && p.kind != engine::PointKind::kPark) {
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
  auto it = b.index.find(seq);
  return it == b.index.end() ? -1 : static_cast<long>(it->second);
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

double GateImpl::Departure(const GateBot& b, long i) const {
  if (i < 0) return 0.0;
  const engine::Waypoint& w = b.plan.waypoints[static_cast<std::size_t>(i)];
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

// The formation segment of order `o` in b's plan: join index J (first waypoint of the run at
// the rendezvous point before the slot), F (the formation's first pick), E (its drop).
std::optional<GateImpl::TeamSpan> GateImpl::SpanOf(const GateBot& b, const std::string& o) const {
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

bool GateImpl::IsStop(const engine::Waypoint& w) {
  return w.action != WaypointAction::kMove || w.dwell > 0.0;
}

// --- Solo agents --------------------------------------------------------------------------

bool GateImpl::OnFloor(const GateBot& b) const { return b.ctl >= 0 && !ctl.removed(static_cast<std::size_t>(b.ctl)); }

bool GateImpl::PlaceBot(GateBot& b, PointId at) {
  if (at == engine::kNoPoint) return false;
  if (b.ctl < 0) {
    auto added = ctl.AddRobot(b.id, at);
    if (!added.ok()) return false;
    b.ctl = static_cast<int>(*added);
  } else if (ctl.removed(static_cast<std::size_t>(b.ctl))) {
    if (!ctl.Place(static_cast<std::size_t>(b.ctl), at).ok()) return false;
  } else {
    return true;
  }
  b.leg_stale = true;
  b.left = false;
  return true;
}

// Re-places a bot that is not on the floor at the free point nearest to where it is.
bool GateImpl::PlaceNear(GateBot& b) {
  std::vector<PointId> candidates;
  const long n = static_cast<long>(b.plan.waypoints.size());
  if (b.idx >= 0 && b.idx < n) candidates.push_back(b.plan.waypoints[static_cast<std::size_t>(b.idx)].point);
  if (b.idx + 1 < n) candidates.push_back(b.plan.waypoints[static_cast<std::size_t>(b.idx + 1)].point);
  if (b.has_xy) candidates.push_back(map->NearestPoint(b.xy));
  if (b.ctl >= 0) {  // teammates (a formation it is in or just left) do not keep it off
    const auto keys = TeamKeys(b);
    ctl.SetGroup(static_cast<std::size_t>(b.ctl), keys.first.empty() ? 0 : GroupOf(keys.first),
                 keys.second.empty() ? 0 : GroupOf(keys.second));
  }
  for (PointId p : candidates) {
    if (PlaceBot(b, p)) return true;
  }
  return false;
}

// Rewrites b's waypoints after index `cut` (-1: a new anchor too) with moves along `route`
// (route[0] = the point it stands at), then continues with the old waypoints from `resume`
// on (re-sequenced and re-timed; -1: none); returns the new index of `resume` (or -1). When the old waypoint at `resume` is at the
// route's last point it stands for that point (a stop keeps its action and dwell).
long GateImpl::RewriteLeg(GateBot& b, long cut, const std::vector<PointId>& route, long resume, double t,
                          std::vector<GateEffect>& out, const Offset& offset) {
  const std::vector<engine::Waypoint> old = b.plan.waypoints;
  const std::vector<std::string> old_orders = b.plan.order_of;
  std::vector<engine::Waypoint> w(old.begin(), old.begin() + (cut + 1));
  std::vector<std::string> ow(old_orders.begin(), old_orders.begin() + (cut + 1));
  const std::uint64_t from = cut + 1 < static_cast<long>(old.size())
                                 ? static_cast<std::uint64_t>(old[static_cast<std::size_t>(cut + 1)].seq)
                                 : b.plan.next_sequence;
  double clock = std::max(t, cut >= 0 ? Departure(b, cut) : t);
  const std::string order = resume >= 0 ? old_orders[static_cast<std::size_t>(resume)] : std::string();
  auto move = [&](PointId p, PointId prev) {
    engine::Waypoint m;
    m.seq = static_cast<int>(b.plan.next_sequence++);
    m.point = p;
    m.xy = map->point(p).position + (offset ? offset(prev, p) : Eigen::Vector2d::Zero());
    m.eta = clock;
    m.action = WaypointAction::kMove;
    w.push_back(m);
    ow.push_back(w.size() == 1 ? std::string() : order);
  };
  if (cut < 0) move(route.front(), route.front());  // the anchor: where it stands
  Eigen::Vector2d at = map->point(route.front()).position;
  for (std::size_t k = 1; k < route.size(); ++k) {
    const Eigen::Vector2d xy = map->point(route[k]).position;
    clock += (xy - at).norm() / std::max(1e-6, config.speed);
    at = xy;
    if (k + 1 == route.size() && resume >= 0 && old[static_cast<std::size_t>(resume)].point == route[k]) break;
    move(route[k], route[k - 1]);
  }
  const long resumed = resume >= 0 ? static_cast<long>(w.size()) : -1;
  if (resume >= 0) {
    const double shift = std::max(0.0, clock - old[static_cast<std::size_t>(resume)].eta);
    for (long i = resume; i < static_cast<long>(old.size()); ++i) {
      engine::Waypoint m = old[static_cast<std::size_t>(i)];
      m.seq = static_cast<int>(b.plan.next_sequence++);
      m.eta += shift;
      w.push_back(m);
      ow.push_back(old_orders[static_cast<std::size_t>(i)]);
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
  b.index.clear();
  for (std::size_t i = 0; i < b.plan.waypoints.size(); ++i) {
    b.index[static_cast<std::uint64_t>(b.plan.waypoints[i].seq)] = i;
    b.plan.next_sequence = std::max<std::uint64_t>(b.plan.next_sequence, b.plan.waypoints[i].seq + 1);
  }
  b.idx = -1;
  for (long i = static_cast<long>(b.plan.waypoints.size()) - 1; i >= 0; --i) {
    if (static_cast<std::uint64_t>(b.plan.waypoints[static_cast<std::size_t>(i)].seq) <= b.reached_seq) {
      b.idx = i;
      break;
    }
  }
}

// One solo agent standing or driving: releases, requests, rewrites.
void GateImpl::StepSolo(GateBot& b, double t, std::vector<GateEffect>& out) {
  if (!b.team.empty()) return;
  if (!OnFloor(b)) {
    if (!PlaceNear(b)) return;
  }
  const auto r = static_cast<std::size_t>(b.ctl);
  const auto& w = b.plan.waypoints;
  const long n = static_cast<long>(w.size());
  // On its way to a rendezvous, or leaving one, a member may come closer to its teammates.
  const auto keys = TeamKeys(b);
  ctl.SetGroup(r, keys.first.empty() ? 0 : GroupOf(keys.first), keys.second.empty() ? 0 : GroupOf(keys.second));
  const PointId next = ctl.Next(r);
  if (next != engine::kNoPoint) {  // driving: the point behind is released once clear of it
    // Clear of it by eps2 (Chu2024 eq. (11)): a formation may be given the point behind.
    if (!b.left && b.has_xy &&
        (b.xy - map->point(ctl.At(r)).position).norm() >= config.point_clearance + engine::FormationRadius()) {
      ctl.LeftPoint(r);
      b.left = true;
    }
    Release(b, RunEnd(b, b.idx + 1, next, n), map->IntersectionOf(next), out);
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
    JoinTeam(b, join_order, t, out);
    return;
  }
  if (here + 1 >= n) {  // nothing ahead: idle
    ctl.SetIdle(r, true);
    bool aside = false;
    if (!ctl.HasRoute(r) && !b.stepped_aside && blocks_service[static_cast<std::size_t>(at)]) {
      // Out of the way of the next robot to serve here: a siding nearby, else home.
      aside = ctl.StepAside(r, {at});
      if (!aside && b.home != engine::kNoPoint && b.home != at) {
        auto path = routes->Path(at, b.home);
        aside = path.ok() && ctl.SetRoute(r, path->points).ok();
      }
    }
    if (aside) {
      b.stepped_aside = true;
      RewriteLeg(b, here, ctl.RemainingRoute(r), -1, t, out);  // a nudge: moves appended
      b.leg = ctl.RemainingRoute(r);
      b.leg_stop = -1;
      b.leg_stale = false;
    }
    if (!ctl.HasRoute(r)) return;
    if (b.leg_stale || ctl.RemainingRoute(r) != b.leg) {
      // The controller moves it (a nudge or back-off in deadlock breaking): the plan follows.
      RewriteLeg(b, here, ctl.RemainingRoute(r), -1, t, out);
      b.leg = ctl.RemainingRoute(r);
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
      const bool same = from_plan && leg == ctl.RemainingRoute(r);
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
    b.leg = ctl.RemainingRoute(r);
    b.leg_stale = false;
    if (!ctl.HasRoute(r)) return;
  }
  RequestSolo(b, t, out);
}

void GateImpl::RequestSolo(GateBot& b, double t, std::vector<GateEffect>& out) {
  const auto r = static_cast<std::size_t>(b.ctl);
  for (int attempt = 0; attempt < 3; ++attempt) {
    const TrafficDecision d = ctl.Request(r, t);
    if (d == TrafficDecision::kGo) {
      b.left = false;
      b.blocked = false;
      const PointId next = ctl.Next(r);
      Release(b, RunEnd(b, b.idx + 1, next, static_cast<long>(b.plan.waypoints.size()) - 1),
              map->IntersectionOf(next), out);
      return;
    }
    if (d == TrafficDecision::kWait) {
      Hold(b, ctl.why(r), out);
      return;
    }
    if (d == TrafficDecision::kBlocked) {
      if (!b.blocked) {
        b.blocked = true;
        GateEffect e;
        e.kind = GateEffect::Kind::kBlocked;
        e.robot = b.id;
        e.reason = ctl.why(r);
        out.push_back(std::move(e));
      }
      Hold(b, "blocked: " + ctl.why(r), out);
      return;
    }
    AdoptRoute(b, t, out);  // kReplanned: the controller's detour becomes the leg
  }
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
    if (ctl.Next(r) != engine::kNoPoint && p == ctl.Next(r)) {
      ctl.Arrived(r, t);
      b.leg = ctl.RemainingRoute(r);
      b.stepped_aside = false;  // idle where it arrived: may have to step aside again
      // Out of the formation's envelope around where it left the team: one agent of its own.
      const double envelope = config.point_clearance + engine::FormationRadius();
      auto teammates_out = [&] {  // nobody of its former team still stands in a slot there
        if (b.former_at == engine::kNoPoint) return true;
        const Eigen::Vector2d& d = map->point(b.former_at).position;
        for (const auto& [id, o] : bots) {
          if (&o == &b || (o.former_team != b.former_team && o.team != b.former_team)) continue;
          if (!o.has_xy || (o.xy - d).norm() < envelope - 1e-9) return false;
        }
        return true;
      };
      if (!b.former_team.empty() && !teams.count(b.former_team) &&
          (b.former_at == engine::kNoPoint ||
           (map->point(ctl.At(r)).position - map->point(b.former_at).position).norm() >= envelope - 1e-9) &&
          teammates_out()) {
        b.former_team.clear();
        ctl.SetEnvelope(r, 0.0);
      }
    }
  }
}

// --- Minimum distance ---------------------------------------------------------------------

// The formation orders a robot counts as one agent with: the team it is in or approaches,
// and the team it left at its last drop until it (and its teammates) have driven off.
std::pair<std::string, std::string> GateImpl::TeamKeys(const GateBot& b) const {
  if (b.team.empty() && b.former_team.empty() && b.plan.teams.empty()) return {};  // a robot alone
  std::string current = b.team;
  if (current.empty()) {
    const long i = std::min<long>(b.idx + 1, static_cast<long>(b.plan.order_of.size()) - 1);
    if (i >= 0) {
      const std::string& o = b.plan.order_of[static_cast<std::size_t>(i)];
      if (!o.empty() && b.plan.teams.count(o)) current = o;
    }
  }
  return {current, b.former_team};
}

void GateImpl::SampleDistances(double t) {
  struct Item {
    const GateBot* bot;
    std::pair<std::string, std::string> keys;
  };
  auto same_agent = [](const Item& a, const Item& b) {
    for (const std::string* x : {&a.keys.first, &a.keys.second}) {
      if (!x->empty() && (*x == b.keys.first || *x == b.keys.second)) return true;
    }
    return false;
  };
  std::unordered_map<long long, std::vector<Item>> cells;
  auto key = [](long long x, long long y) { return (x << 32) ^ (y & 0xffffffffLL); };
  for (auto& [id, b] : bots) {
    if (!b.has_xy || !b.connected) continue;
    const long long cx = static_cast<long long>(std::floor(b.xy.x()));
    const long long cy = static_cast<long long>(std::floor(b.xy.y()));
    const Item me{&b, TeamKeys(b)};
    for (long long dx = -1; dx <= 1; ++dx) {
      for (long long dy = -1; dy <= 1; ++dy) {
        auto it = cells.find(key(cx + dx, cy + dy));
        if (it == cells.end()) continue;
        for (const Item& o : it->second) {
          if (same_agent(o, me)) continue;
          const double d = (o.bot->xy - b.xy).norm();
          if (d < min_distance.distance) min_distance = {d, o.bot->id, b.id, t};
        }
      }
    }
    cells[key(cx, cy)].push_back(me);
  }
}

// --- Public interface ----------------------------------------------------------------------

void TrafficGate::Connect(const std::string& robot, const Eigen::Vector2d& xy, PointId point) {
  Impl& s = *impl_;
  GateBot& b = s.bots[robot];
  b.id = robot;
  b.connected = true;
  b.synced = false;
  b.resume_pending = true;  // it may still hold on a Hold from before the stream broke
  b.held = false;
  const engine::PointKind kind = s.map->point(point).kind;
  if (b.home == engine::kNoPoint && (kind == engine::PointKind::kPark || kind == engine::PointKind::kCharge)) {
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
  auto it = impl_->bots.find(robot);
  if (it != impl_->bots.end()) it->second.connected = false;
}

void TrafficGate::SetPlan(const std::string& robot, GatePlan plan) {
  Impl& s = *impl_;
  GateBot& b = s.bots[robot];
  b.id = robot;
  if (plan.order_of.size() != plan.waypoints.size()) plan.order_of.resize(plan.waypoints.size());
  plan.next_sequence = std::max(plan.next_sequence, b.plan.next_sequence);
  b.plan = std::move(plan);
  s.Reindex(b);
  b.leg_stale = true;
  if (b.released < b.reached_seq) b.released = b.reached_seq;
  s.SyncTeams(b);
}

void TrafficGate::Reached(const std::string& robot, std::uint64_t sequence, double t) {
  auto it = impl_->bots.find(robot);
  if (it != impl_->bots.end()) impl_->OnReached(it->second, sequence, t);
}

void TrafficGate::Report(const std::string& robot, const Eigen::Vector2d& xy, std::uint64_t last_waypoint,
                         double t) {
  auto it = impl_->bots.find(robot);
  if (it == impl_->bots.end()) return;
  it->second.xy = xy;
  it->second.has_xy = true;
  if (last_waypoint > it->second.reached_seq) impl_->OnReached(it->second, last_waypoint, t);
  it->second.synced = true;
}

std::vector<GateEffect> TrafficGate::Step(double t) {
  Impl& s = *impl_;
  std::vector<GateEffect> out;
  s.next_wake = std::numeric_limits<double>::infinity();
  // A reconnected robot may still obey a Hold whose Resume was lost with its old stream: it
  // gets a Resume with its horizon (the horizon, not the Hold, is what keeps it safe), and a
  // Hold again if it must still wait.
  for (auto& [id, b] : s.bots) {
    if (!b.resume_pending || !b.connected) continue;
    b.resume_pending = false;
    b.held = true;  // sent as a Resume
    s.SendRelease(b, -1, out);
  }
  s.StepTeams(t, out);
  for (auto& [id, b] : s.bots) s.StepSolo(b, t, out);
  // Deadlock breaking and nudges re-route standing robots: their legs follow.
  s.ctl.ResolveDeadlocks(t);
  for (auto& [id, b] : s.bots) {
    if (!b.team.empty() || !s.OnFloor(b) || !b.connected || b.leg_stale) continue;
    const auto r = static_cast<std::size_t>(b.ctl);
    if (s.ctl.Next(r) == engine::kNoPoint && s.ctl.RemainingRoute(r) != b.leg) s.AdoptRoute(b, t, out);
  }
  s.StepTeamsAfterDeadlocks(t, out);
  return out;
}

void TrafficGate::SampleDistances(double t) { impl_->SampleDistances(t); }

double TrafficGate::NextWake() const { return impl_->next_wake; }

bool TrafficGate::Available(const std::string& robot) const {
  auto it = impl_->bots.find(robot);
  return it == impl_->bots.end() || it->second.team.empty() ||
         impl_->teams.count(it->second.team) == 0 ||
         impl_->teams.at(it->second.team).phase != GateTeam::Phase::kLeaving;
}

PointId TrafficGate::StartPoint(const std::string& robot) const {
  const Impl& s = *impl_;
  auto it = s.bots.find(robot);
  if (it == s.bots.end() || !it->second.team.empty() || !s.OnFloor(it->second)) return engine::kNoPoint;
  const auto r = static_cast<std::size_t>(it->second.ctl);
  return s.ctl.Next(r) != engine::kNoPoint ? s.ctl.Next(r) : s.ctl.At(r);
}

std::uint64_t TrafficGate::ReleasedUpTo(const std::string& robot) const {
  auto it = impl_->bots.find(robot);
  return it == impl_->bots.end() ? 0 : it->second.released;
}

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
  const auto keys = s.TeamKeys(b);
  if (!keys.first.empty() || !keys.second.empty()) out += "; team keys " + keys.first + "/" + keys.second;
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
  const engine::IntersectionGrants& grants = s.ctl.grants();
  std::vector<GateIntersection> out(grants.guard_count());
  for (std::size_t g = 0; g < out.size(); ++g) {
    out[g].holders = robots_of(grants.Holders(g));
    out[g].waiting = robots_of(grants.Queue(g));
  }
  return out;
}

GateRobotState TrafficGate::RobotState(const std::string& robot) const {
  GateRobotState state;
  auto it = impl_->bots.find(robot);
  if (it == impl_->bots.end()) return state;
  state.held = it->second.held;
  if (state.held) state.reason = it->second.hold_reason;
  state.formation = it->second.team;
  return state;
}

const MinDistance& TrafficGate::min_distance() const { return impl_->min_distance; }
const engine::TrafficStats& TrafficGate::stats() const { return impl_->ctl.stats(); }

}  // namespace dispatch::server
