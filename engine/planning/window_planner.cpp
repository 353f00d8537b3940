#include "engine/planning/window_planner.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <queue>
#include <string>
#include <tuple>
#include <unordered_map>
#include <utility>

#include "engine/common/numbers.h"

namespace dispatch::engine {
namespace {

using Interval = std::pair<double, double>;

struct WindowNode {
  PointId p = kNoPoint;
  int interval = 0;     // index into the point's free intervals
  ArcId came = -1;      // the arc it arrived by (-1: none, or no turning time)
  double arrive = 0.0;  // earliest arrival in the interval (at a stop's start: when it may leave)
  int parent = -1;
  double left_parent = 0.0;  // when it left the parent's point
};

struct Key {
  PointId p;
  int interval;
  ArcId came;
  bool operator==(const Key& o) const { return p == o.p && interval == o.interval && came == o.came; }
};
struct KeyHash {
  std::size_t operator()(const Key& k) const {
    std::size_t h = std::hash<long long>{}(static_cast<long long>(k.p) * 1000003LL + k.interval);
    return h * 31u ^ std::hash<int>{}(k.came);
  }
};

// One stop's search state: the free intervals seen so far and the route table's scale.
class StopSearch {
 public:
  StopSearch(const ReservationTable& table, const RouteTable& routes, int robot, const PlanLimits& limits)
      : table_(table), routes_(routes), robot_(robot), limits_(limits), map_(table.map()),
        rules_(table.rules()), clear_(rules_.ClearTime()) {
    const double table_speed = routes.build_info().speed;
    scale_ = table_speed > 0.0 ? table_speed / rules_.speed : 1.0;
  }

  const std::vector<Interval>& Free(PointId p) {
    auto it = free_.find(p);
    if (it == free_.end()) it = free_.emplace(p, table_.FreeIntervals(p, robot_)).first;
    return it->second;
  }

  // The free interval of p holding time t (t < its end), or -1.
  int IntervalAt(PointId p, double t) {
    const auto& f = Free(p);
    for (std::size_t k = 0; k < f.size(); ++k) {
      if (f[k].first <= t + kEps && t < f[k].second - kEps) return static_cast<int>(k);
    }
    return -1;
  }

  // From `from` (standing at its point since `since`, ready at from.arrive) to `goal`, to
  // stand there `work` s (for ever when `forever`). Appends the visits up to the goal to
  // `route` (the goal's depart = arrival + work, or kForever) and returns the goal's node.
  Result<WindowNode> Run(WindowNode from, double since, PointId goal, double work, bool forever, TimedRoute& route,
                   std::size_t& expanded) {
    std::vector<WindowNode> nodes{from};
    std::unordered_map<Key, double, KeyHash> best;
    using Entry = std::tuple<double, double, int>;  // f, -arrival (later first: nearer), node
    std::priority_queue<Entry, std::vector<Entry>, std::greater<>> open;
    auto h = [&](PointId p) { return routes_.Cost(p, goal) * scale_; };
    // No arrival at the goal comes before the first free interval there that can hold the
    // stop: a bound on every f (else, when the goal is held for long, the search would sweep
    // every state it could wait in before then).
    double goal_from = kForever;
    const double soonest = from.arrive + h(from.p);
    for (const Interval& f : Free(goal)) {
      const bool holds = forever ? std::isinf(f.second) : f.second - f.first >= work + clear_;
      if (holds && f.second > soonest + work + clear_) {
        goal_from = std::max(f.first, soonest);
        break;
      }
    }
    if (std::isinf(goal_from)) {
      return Unreachable("time windows: point " + map_.point(goal).name + " is never free long enough");
    }
    auto f_of = [&](double arrive, double h_p) { return std::max(arrive + h_p, goal_from); };
    auto key_of = [&](const WindowNode& n) { return Key{n.p, n.interval, rules_.turn_s_per_90 > 0.0 ? n.came : -1}; };
    best[key_of(from)] = from.arrive;
    open.push({f_of(from.arrive, h(from.p)), -from.arrive, 0});
    std::size_t local = 0;
    while (!open.empty()) {
      const int index = std::get<2>(open.top());
      open.pop();
      const WindowNode n = nodes[static_cast<std::size_t>(index)];
      if (best[key_of(n)] < n.arrive - kEps) continue;  // a better arrival was found since
      const Interval span = Free(n.p)[static_cast<std::size_t>(n.interval)];
      if (n.p == goal && (forever ? std::isinf(span.second) : n.arrive + work + clear_ <= span.second + kEps)) {
        Emit(nodes, index, since, work, forever, route);
        return nodes[static_cast<std::size_t>(index)];
      }
      ++expanded;
      ++local;
      if ((limits_.max_expansions > 0 && local >= limits_.max_expansions) ||
          ((local & 255u) == 0 && limits_.stop && limits_.stop())) {
        return Error{ErrorCode::kFailedPrecondition, "time windows: stopped after " + std::to_string(local) +
                                                         " expansions towards point " + map_.point(goal).name};
      }
      const double latest = span.second - clear_;  // it must be clear of n.p when its interval ends
      for (ArcId a : map_.out_arcs(n.p)) {
        const PointId q = map_.arc(a).to;
        const double hq = h(q);
        if (std::isinf(hq)) continue;
        const double drive = DriveTime(map_, rules_, a);
        const double earliest = n.arrive + TurnTime(map_, rules_, n.came, a);
        if (earliest > latest + kEps) continue;
        const auto& free_q = Free(q);
        const auto first = std::upper_bound(free_q.begin(), free_q.end(), earliest + drive + kEps,
                                            [](double t, const Interval& x) { return t < x.second; });
        for (auto m = static_cast<std::size_t>(first - free_q.begin()); m < free_q.size(); ++m) {
          if (free_q[m].first > latest + drive + kEps) break;
          const double leave = LeaveTime(a, std::max(earliest, free_q[m].first - drive), drive);
          if (leave > latest + kEps || leave + drive >= free_q[m].second - kEps) continue;
          WindowNode next{q, static_cast<int>(m), a, leave + drive, index, leave};
          auto [it, fresh] = best.try_emplace(key_of(next), next.arrive);
          if (!fresh) {
            if (it->second <= next.arrive + kEps) continue;
            it->second = next.arrive;
          }
          nodes.push_back(next);
          open.push({f_of(next.arrive, hq), -next.arrive, static_cast<int>(nodes.size()) - 1});
        }
      }
    }
    return Unreachable("time windows: no route to point " + map_.point(goal).name + " through the free windows");
  }

 private:
  // The earliest time >= t to leave along arc a (driving `drive` s) that meets no robot
  // coming the other way and keeps the lane within its capacity (eqs. (10)-(11)).
  double LeaveTime(ArcId a, double t, double drive) const {
    const Arc& arc = map_.arc(a);
    const int capacity = std::max(1, static_cast<int>(std::floor(arc.length / rules_.body_length + 1e-9)));
    for (int guard = 0; guard < 1000; ++guard) {
      const double opposite = table_.OppositeFreeFrom(a, t, drive, robot_);
      if (opposite > t + kEps) {
        t = opposite;
        continue;
      }
      if (table_.SameDirectionDuring(a, t, t + drive, robot_) < capacity) return t;
      double next = kForever;  // leave when the first of those on the lane has left it
      for (const TimeWindow& w : table_.ArcWindows(a)) {
        if (w.robot != robot_ && w.from < t + drive - kEps && t < w.to - kEps) next = std::min(next, w.to);
      }
      t = next;
    }
    return kForever;
  }

  // The visits from the stop's start to node `last` (the start's visit began at `since`).
  static void Emit(const std::vector<WindowNode>& nodes, int last, double since, double work, bool forever,
                   TimedRoute& route) {
    std::vector<int> chain;
    for (int k = last; k >= 0; k = nodes[static_cast<std::size_t>(k)].parent) chain.push_back(k);
    std::reverse(chain.begin(), chain.end());
    for (std::size_t i = 0; i < chain.size(); ++i) {
      const WindowNode& n = nodes[static_cast<std::size_t>(chain[i])];
      TimedVisit v{n.p, i == 0 ? since : n.arrive, 0.0};
      if (i + 1 < chain.size()) {
        v.depart = nodes[static_cast<std::size_t>(chain[i + 1])].left_parent;
      } else {
        v.depart = forever ? kForever : n.arrive + work;
      }
      route.push_back(v);
    }
  }

  const ReservationTable& table_;
  const RouteTable& routes_;
  int robot_;
  const PlanLimits& limits_;
  const WarehouseMap& map_;
  const TimeWindowRules& rules_;
  double clear_;
  double scale_ = 1.0;
  std::unordered_map<PointId, std::vector<Interval>> free_;
};

}  // namespace

Result<WindowPlan> PlanInWindows(const ReservationTable& table, const RouteTable& routes, const WindowRequest& request,
                                 const PlanLimits& limits) {
  const WarehouseMap& map = table.map();
  auto valid = [&](PointId p) { return p >= 0 && static_cast<std::size_t>(p) < map.point_count(); };
  const std::string who = "robot " + std::to_string(request.robot);
  if (!valid(request.start)) return InvalidArgument(who + ": start " + std::to_string(request.start) + " is not on the map");
  if (!std::isfinite(request.start_time)) return InvalidArgument(who + ": start time must be finite");
  for (const WindowStop& s : request.stops) {
    if (!valid(s.point)) return InvalidArgument(who + ": stop " + std::to_string(s.point) + " is not on the map");
    if (!(s.work_s >= 0.0) || std::isinf(s.work_s)) return InvalidArgument(who + ": work time must be finite and >= 0");
  }
  StopSearch search(table, routes, request.robot, limits);
  const int first = search.IntervalAt(request.start, request.start_time);
  if (first < 0) {
    return Unreachable(who + ": its start " + map.point(request.start).name + " is held by another robot at " +
                       std::to_string(request.start_time));
  }
  WindowPlan out;
  WindowNode at{request.start, first, -1, request.start_time, -1, 0.0};
  double since = request.start_time;
  std::vector<WindowStop> stops = request.stops;
  const bool stand = stops.empty();
  if (stand) stops.push_back({request.start, 0.0});  // stays where it is
  for (std::size_t k = 0; k < stops.size(); ++k) {
    const bool last = k + 1 == stops.size();
    TimedRoute leg;
    auto reached = search.Run(at, since, stops[k].point, stops[k].work_s, last && request.stay_at_end, leg, out.expanded);
    if (!reached.ok()) return Error{reached.error().code, who + ": " + reached.error().message};
    if (!out.route.empty()) out.route.pop_back();  // the stop's visit continues in this leg
    out.route.insert(out.route.end(), leg.begin(), leg.end());
    out.stop_visits.push_back(out.route.size() - 1);
    at = reached.value();
    at.parent = -1;
    since = at.arrive;
    at.arrive += stops[k].work_s;  // ready to leave once the work is done
  }
  if (stand) out.stop_visits.clear();
  return out;
}

Result<PrioritizedPlans> PlanInPriorityOrder(ReservationTable& table, const RouteTable& routes,
                                             const std::vector<WindowRequest>& requests, const PlanLimits& limits) {
  PrioritizedPlans out;
  out.routes.resize(requests.size());
  out.errors.resize(requests.size());
  out.order.resize(requests.size());
  std::iota(out.order.begin(), out.order.end(), 0);
  std::stable_sort(out.order.begin(), out.order.end(), [&](std::size_t a, std::size_t b) {
    if (requests[a].working != requests[b].working) return requests[a].working;
    return requests[a].release_time < requests[b].release_time;
  });
  for (std::size_t i : out.order) {
    if (limits.stop && limits.stop()) {
      return Error{ErrorCode::kFailedPrecondition, "time windows: stopped with " + std::to_string(i) + " robots planned"};
    }
    auto plan = PlanInWindows(table, routes, requests[i], limits);
    if (!plan.ok()) {
      if (plan.error().code == ErrorCode::kFailedPrecondition) return plan.error();
      out.errors[i] = plan.error();
      table.Release(requests[i].robot);
      continue;
    }
    out.expanded += plan.value().expanded;
    if (Status ok = table.Reserve(requests[i].robot, plan.value().route); !ok.ok()) return ok.error();
    out.routes[i] = std::move(plan.value().route);
  }
  return out;
}

}  // namespace dispatch::engine
