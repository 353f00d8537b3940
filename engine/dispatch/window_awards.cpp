#include "engine/dispatch/window_awards.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <random>

#include "engine/planning/window_planner.h"

namespace dispatch::engine {
namespace {

// Seconds a robot whose plan ends at a service point (a pick or drop) holds it after its work
// there: an idle robot by a service point steps aside at once (TrafficGate), so the windows do
// not keep the point for ever (which left every later robot with a stop there unplanned).
constexpr double kParkSeconds = 5.0;

// How long a plan's last visit at `p` lasts from its departure: kParkSeconds at a service
// point, else for ever (the robot stays).
double ParkedFor(const WarehouseMap& map, PointId p) {
  return IsServicePoint(map.point(p).kind) ? kParkSeconds : kForever;
}

// The visits of `w` as a route the table accepts: waypoints at one point in a row are one
// visit, no arrival faster than its arc allows, the last visit parked (ParkedFor). Empty when
// two points in a row are not joined by an arc (the plan is then not reserved).
TimedRoute VisitsOf(const WarehouseMap& map, const TimeWindowRules& rules, const std::vector<Waypoint>& w) {
  TimedRoute r;
  for (const Waypoint& x : w) {
    if (!r.empty() && r.back().point == x.point) {
      r.back().depart = std::max(r.back().depart, x.departure());
      continue;
    }
    double arrive = x.eta;
    if (!r.empty()) {
      const auto arc = map.FindArc(r.back().point, x.point);
      if (!arc) return {};
      arrive = std::max(arrive, r.back().depart + DriveTime(map, rules, *arc));
    }
    r.push_back({x.point, arrive, std::max(arrive, x.departure())});
  }
  if (!r.empty()) r.back().depart += ParkedFor(map, r.back().point);
  return r;
}

// Whether a waypoint of `w` from `first` on carries a heading: a segment refined through
// free space (FleetState::UseFreeSpace), which the graph's windows cannot plan again.
bool Posed(const std::vector<Waypoint>& w, std::size_t first) {
  for (std::size_t k = first; k < w.size(); ++k) {
    if (w[k].heading) return true;
  }
  return false;
}

// The re-planned segment as waypoints (see the header: waits become departures). `fresh`:
// the segment starts with the robot's start waypoint; else it follows its queue, which it
// leaves at `ready`. A stop may be worked at the route's first visit (where the queue ends, or
// where a fresh robot stands) and several stops at one visit: each gets its waypoint there.
std::vector<Waypoint> SegmentOf(const WarehouseMap& map, const WindowPlan& plan, const std::vector<Waypoint>& stops,
                                bool fresh, double ready, const Waypoint& first) {
  std::vector<Waypoint> out;
  const TimedRoute& r = plan.route;
  std::size_t next_stop = 0;
  for (std::size_t v = 0; v < r.size(); ++v) {
    const bool last = v + 1 == r.size();
    std::size_t stops_end = next_stop;  // the stops worked at this visit: [next_stop, stops_end)
    while (stops_end < stops.size() && stops_end < plan.stop_visits.size() && plan.stop_visits[stops_end] == v) {
      ++stops_end;
    }
    Waypoint wp;
    wp.point = r[v].point;
    wp.xy = map.point(wp.point).position;
    wp.action = WaypointAction::kMove;
    wp.eta = last ? r[v].arrive : r[v].depart;
    if (v == 0) {
      if (fresh) {
        wp.action = first.action;
        if (stops_end > next_stop) wp.eta = r[0].arrive;  // it works here first
        out.push_back(wp);
      } else if (stops_end == next_stop && r[0].depart > ready + 1e-6) {
        out.push_back(wp);  // it waits where its queue ended
      }
      if (stops_end == next_stop) continue;
    } else if (stops_end == next_stop) {
      out.push_back(wp);
      continue;
    }
    // The stops here, one waypoint each: the work ends at the visit's departure (the last
    // visit: starts at its arrival), so a wait before it is spent before the first one.
    double dwell_after = 0.0;
    for (std::size_t k = next_stop; k < stops_end; ++k) dwell_after += stops[k].dwell;
    double at = last ? r[v].arrive : r[v].depart - dwell_after;
    for (; next_stop < stops_end; ++next_stop) {
      const Waypoint& stop = stops[next_stop];
      wp.action = stop.action;
      wp.dwell = stop.dwell;
      wp.eta = at;
      at += stop.dwell;
      out.push_back(wp);
    }
  }
  return out;
}

// The round's reservations: every robot's plan up to where this round's new segment begins
// (all of it for robots that are not re-planned: no new single-robot segment, or a formation
// won in the round), in one table; `kept` grows as segments are planned.
struct RoundWindows {
  TimeWindowRules rules;
  ReservationTable table;
  std::vector<bool> replan;
  std::vector<std::vector<Waypoint>> kept;

  RoundWindows(const std::shared_ptr<const WarehouseMap>& map, const AllocationConfig& config, const FleetState& fleet,
               const RoundSegments& segments, std::vector<std::string>& notes)
      : rules(RulesOf(config)), table(map, rules), replan(fleet.robot_count(), false), kept(fleet.robot_count()) {
    for (std::size_t i = 0; i < fleet.robot_count(); ++i) {
      const auto& w = fleet.plan(i).waypoints;
      const std::size_t first = i < segments.first_new.size() ? segments.first_new[i] : RoundSegments::kNothingNew;
      // A four-wheel-steer robot's segment refined through free space (its waypoints posed)
      // keeps its route and is reserved as it is, as a formation's.
      replan[i] = first != RoundSegments::kNothingNew && !segments.in_formation[i] && !Posed(w, first);
      // A robot without a queue keeps its start waypoint; its new segment repeats it.
      const std::size_t upto = replan[i] ? std::max<std::size_t>(first, 1) : w.size();
      kept[i].assign(w.begin(), w.begin() + static_cast<std::ptrdiff_t>(std::min(upto, w.size())));
      if (!Reserve(i) && replan[i]) {
        replan[i] = false;
        notes.push_back("time windows: the plan of " + fleet.robot_id(i) +
                        " is not a route of the map; its awards keep the strategy's routes");
      }
    }
  }
  static TimeWindowRules RulesOf(const AllocationConfig& config) {
    TimeWindowRules r = config.windows;
    r.speed = config.speed;
    r.turn_s_per_90 = config.turn_time;
    return r;
  }
  bool Reserve(std::size_t i) {
    const TimedRoute route = VisitsOf(table.map(), rules, kept[i]);
    if (route.empty() || !table.Reserve(static_cast<int>(i), route).ok()) {
      table.Release(static_cast<int>(i));
      return false;
    }
    return true;
  }
};

// One award to plan: its robot's request from where (and when) its queue ends.
struct AwardJob {
  std::size_t award = 0;
  std::size_t robot = 0;
  bool fresh = false;  // the segment starts with the robot's start waypoint
  double ready = 0.0;
  WindowRequest request;
  std::vector<Waypoint> stops;
};

// The job of award `a` for robot i whose queue (as kept) ends with `end`; nullopt when the
// award has nothing to plan.
std::optional<AwardJob> JobOf(const WarehouseMap& map, const RoundAward& a, std::size_t index, std::size_t i,
                              const std::vector<Waypoint>& kept, double now) {
  const std::vector<Waypoint>& segment = a.segments[0];
  if (segment.empty() || kept.empty()) return std::nullopt;
  AwardJob job;
  job.award = index;
  job.robot = i;
  job.fresh = kept.size() == 1 && segment.front().point == kept.front().point && segment.front().seq == kept.front().seq;
  const Waypoint& end = kept.back();
  job.ready = job.fresh ? now : std::max(end.eta, end.departure());
  job.request.robot = static_cast<int>(i);
  job.request.start = end.point;
  job.request.start_time = job.ready;
  for (const Waypoint& w : segment) {
    if (w.action == WaypointAction::kPick || w.action == WaypointAction::kDrop) {
      job.stops.push_back(w);
      job.request.stops.push_back({w.point, w.dwell});
    }
  }
  if (job.stops.empty()) return std::nullopt;
  // Its last stop is held for ever only where the robot will stay (ParkedFor).
  job.request.stay_at_end = std::isinf(ParkedFor(map, job.request.stops.back().point));
  return job;
}

}  // namespace

void PlanAwardsInWindows(const std::shared_ptr<const WarehouseMap>& map, const RouteTable& routes,
                         const AllocationConfig& config, const FleetState& fleet, const RoundSegments& segments,
                         double now, std::vector<RoundAward>& awards, std::vector<std::string>& notes) {
  RoundWindows round(map, config, fleet, segments, notes);
  for (std::size_t k = 0; k < awards.size(); ++k) {
    RoundAward& a = awards[k];
    if (a.award.winners.size() != 1 || a.segments.size() != 1) continue;
    const auto found = fleet.FindRobot(a.award.winners[0]);
    if (!found || !round.replan[*found]) continue;
    const std::size_t i = *found;
    const auto job = JobOf(*map, a, k, i, round.kept[i], now);
    if (!job) continue;
    std::vector<Waypoint>& segment = a.segments[0];
    auto plan = PlanInWindows(round.table, routes, job->request);
    if (plan.ok()) {
      segment = SegmentOf(*map, plan.value(), job->stops, job->fresh, job->ready, segment.front());
      if (!job->fresh) a.after_departure[0] = job->ready;
    } else {
      notes.push_back("order " + a.order_id + ": time windows: " + plan.error().message + "; the strategy's route kept");
    }
    if (job->fresh) round.kept[i].clear();
    round.kept[i].insert(round.kept[i].end(), segment.begin(), segment.end());
    round.Reserve(i);
  }
}

void PlanAwardsByConflictElimination(const std::shared_ptr<const WarehouseMap>& map, const RouteTable& routes,
                                     const AllocationConfig& config, const FleetState& fleet,
                                     const RoundSegments& segments, double now, std::vector<RoundAward>& awards,
                                     std::vector<std::string>& notes) {
  RoundWindows round(map, config, fleet, segments, notes);
  const std::size_t n = fleet.robot_count();
  // Per robot: its awards of the round in order (a robot may win several), the constraints
  // added to it (other robots' windows it must keep out of: pseudo reservations), and its new
  // waypoints as planned.
  std::vector<std::vector<std::size_t>> awards_of(n);
  for (std::size_t k = 0; k < awards.size(); ++k) {
    const RoundAward& a = awards[k];
    if (a.award.winners.size() != 1 || a.segments.size() != 1 || a.segments[0].empty()) continue;
    const auto found = fleet.FindRobot(a.award.winners[0]);
    if (found && round.replan[*found]) awards_of[*found].push_back(k);
  }
  std::vector<std::vector<TimedRoute>> constraints(n);
  std::vector<std::vector<Waypoint>> planned(n);  // the new waypoints of all its awards
  struct Planned {  // one award's segment as planned, and how it follows the robot's queue
    std::vector<Waypoint> segment;
    double ready = 0.0;
    bool fresh = false;
  };
  std::vector<std::vector<Planned>> planned_awards(n);
  std::vector<bool> frozen(n, false);  // no route under its constraints: keeps its last plan
  // Plans robot i's awards one after another, each alone: through the windows of the kept
  // plans and its own constraints only (BIT2024: each robot planned on its own, not through
  // the other re-planned robots' routes). False when an award finds no route.
  auto plan_robot = [&](std::size_t i) {
    const ReservationTable* table = &round.table;
    std::optional<ReservationTable> own;
    if (!constraints[i].empty()) {
      own.emplace(round.table);
      int pseudo = static_cast<int>(n) + 1;
      for (const TimedRoute& c : constraints[i]) (void)own->Reserve(pseudo++, c);
      table = &*own;
    }
    std::vector<Waypoint> queue = round.kept[i];
    std::vector<Planned> segs;
    for (std::size_t k : awards_of[i]) {
      const auto job = JobOf(*map, awards[k], k, i, queue, now);
      if (!job) return false;
      auto plan = PlanInWindows(*table, routes, job->request);
      if (!plan.ok()) return false;
      segs.push_back({SegmentOf(*map, plan.value(), job->stops, job->fresh, job->ready, awards[k].segments[0].front()),
                      job->ready, job->fresh});
      if (job->fresh) queue.clear();
      queue.insert(queue.end(), segs.back().segment.begin(), segs.back().segment.end());
    }
    planned_awards[i] = std::move(segs);
    // From where its queue ends (a fresh robot: its start), so the first arc is checked too.
    const std::size_t from = round.kept[i].empty() ? 0 : std::min(queue.size(), round.kept[i].size() - 1);
    planned[i].assign(queue.begin() + static_cast<std::ptrdiff_t>(from), queue.end());
    return true;
  };
  std::vector<std::size_t> robots;
  for (std::size_t i = 0; i < n; ++i) {
    if (awards_of[i].empty()) continue;
    if (plan_robot(i)) {
      robots.push_back(i);
    } else {
      notes.push_back("conflict elimination: no route through the windows for " + fleet.robot_id(i) +
                      "; its awards keep the strategy's routes");
    }
  }
  // Step 7: the first conflict among the new routes; one of its two robots (seeded random
  // choice) keeps its route, the other is kept out of that one's window and planned again;
  // until no conflict is left or the bound (deterministic, so a replay re-runs the same
  // round). Conflicts with plans kept from before the round cannot arise: every route is
  // planned through their windows.
  std::mt19937_64 rng(0x9E3779B97F4A7C15ull ^ static_cast<std::uint64_t>(now * 1000.0));
  const std::size_t bound = 8 * robots.size() + 8;
  std::size_t iterations = 0;
  for (; iterations < bound; ++iterations) {
    ReservationTable mine(map, round.rules);
    for (std::size_t i : robots) {
      const TimedRoute route = VisitsOf(*map, round.rules, planned[i]);
      if (!route.empty()) (void)mine.Reserve(static_cast<int>(i), route);
    }
    const auto conflict = EarliestConflict(mine);
    if (!conflict) break;
    const auto ra = static_cast<std::size_t>(conflict->a.robot), rb = static_cast<std::size_t>(conflict->b.robot);
    bool keep_a = (rng() & 1u) == 0;
    if (frozen[ra] != frozen[rb]) keep_a = frozen[ra];
    if (frozen[ra] && frozen[rb]) break;  // neither can move: left to the traffic controller
    const std::size_t other = keep_a ? rb : ra;
    const TimeWindow& kept_window = keep_a ? conflict->a : conflict->b;
    TimedRoute c;
    const double clear = round.rules.ClearTime();
    if (conflict->point != kNoPoint) {
      c.push_back({conflict->point, kept_window.from, std::max(kept_window.from, kept_window.to - clear)});
    } else {
      const Arc& arc = map->arc(keep_a ? conflict->arc : map->arc(conflict->arc).reverse_arc);
      c.push_back({arc.from, kept_window.from, kept_window.from});
      c.push_back({arc.to, kept_window.to, kept_window.to});
    }
    constraints[other].push_back(std::move(c));
    if (!plan_robot(other)) {
      constraints[other].pop_back();
      (void)plan_robot(other);  // its plan before the constraint
      frozen[other] = true;
    }
  }
  if (iterations == bound) {
    notes.push_back("conflict elimination: conflicts left after " + std::to_string(bound) +
                    " iterations; the traffic controller resolves them");
  }
  for (std::size_t i : robots) {
    for (std::size_t j = 0; j < awards_of[i].size() && j < planned_awards[i].size(); ++j) {
      RoundAward& a = awards[awards_of[i][j]];
      Planned& p = planned_awards[i][j];
      a.segments[0] = std::move(p.segment);
      if (!p.fresh) a.after_departure[0] = p.ready;
    }
  }
}

}  // namespace dispatch::engine
