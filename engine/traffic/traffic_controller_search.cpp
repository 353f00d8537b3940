// TrafficController's detour search: the cheapest route avoiding a point, a corridor and an
// intersection (bounded A* on the route table's exact times, its answers memoised per query),
// for the ways out of waits in traffic_controller_deadlocks.cpp and the head-on decision.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <queue>
#include <utility>
#include <vector>

#include "engine/traffic/traffic_controller_impl.h"

namespace dispatch::engine {

std::size_t traffic_detail::RouteQueryHash::operator()(const traffic_detail::RouteQuery& q) const {
  std::size_t h = 0;  // the bound is not part of the key
  for (long long v : {static_cast<long long>(q.from), static_cast<long long>(q.to),
                      static_cast<long long>(q.ban_point), static_cast<long long>(q.ban_corridor),
                      static_cast<long long>(q.ban_guard), static_cast<long long>(q.keep_off)}) {
    h = h * 1000003u ^ std::hash<long long>{}(v);
  }
  return h;
}

// Cheapest route from -> to avoiding `ban_point`, corridor `ban_corridor` and intersection
// `ban_guard` (each -1/kNoPoint for none). Empty points when there is none.
// A* with the straight-line time as heuristic (admissible: paths are never shorter than
// the straight distance and no robot is faster than `speed`); searches stop once every
// open route costs more than `bound` seconds (no route returned then).
Detour TrafficController::Impl::Route(PointId from, PointId to, PointId ban_point, int ban_corridor,
                                      int ban_guard, double bound, int keep_off) {
  const traffic_detail::RouteQuery q{from, to, ban_point, ban_corridor, ban_guard, bound, keep_off};
  if (to == ban_point || from == to) return Search(q);
  // A* pops in increasing cost (the heuristic is consistent), so a search under any bound
  // runs as the unbounded one until it stops: it finds the cheapest route when that costs at
  // most the bound, else none. One answer per query serves every bound (a head-on's bound is
  // the wait it saves, new at each conflict).
  auto known = route_memo.find(q);
  if (known != route_memo.end()) {
    const traffic_detail::RouteAnswer& a = known->second;
    if (!a.detour.points.empty()) return a.detour.cost <= bound ? a.detour : Detour{};
    if (bound <= a.bound) return Detour{};
  } else if (route_memo.size() >= kRouteMemo) {
    route_memo.clear();
  }
  traffic_detail::RouteAnswer& a = route_memo[q];
  a.detour = Search(q);
  a.bound = bound;
  return a.detour;
}

double TrafficController::Impl::BoundCost(PointId v, PointId to) {
  if (to != lower_to) {
    lower_to = to;
    if (++lower_stamp == 0) {
      std::fill(lower_seen.begin(), lower_seen.end(), 0);
      lower_stamp = 1;
    }
  }
  const auto i = static_cast<std::size_t>(v);
  if (lower_seen[i] != lower_stamp) {
    lower_seen[i] = lower_stamp;
    lower_memo[i] = bound_routes->Cost(v, to);
  }
  return lower_memo[i];
}

// The cost of Search(q)'s route (+infinity when there is none within q.bound), by A* with
// the route bound's exact unobstructed times as heuristic (consistent: bans only remove
// arcs), which goes straight for the goal where Search's straight-line heuristic sweeps.
// Only the cost: which of several cheapest routes Search returns is its own order's choice.
double TrafficController::Impl::CheapestCost(const traffic_detail::RouteQuery& q) {
  const auto [from, to, ban_point, ban_corridor, ban_guard, bound, keep_off] = q;
  (void)keep_off;  // read by Allowed(q)
  const double inf = std::numeric_limits<double>::infinity();
  const double limit = bound + 1e-6 * (1.0 + std::abs(bound));  // float tables' rounding
  if (++stamp == 0) {
    std::fill(seen.begin(), seen.end(), 0);
    stamp = 1;
  }
  std::vector<OpenItem>& heap = open;  // here h holds the entry's cost so far
  heap.clear();
  const double* costs = bound_routes->CostsTo(to);  // read in place when the table allows
  const PointId target = to;  // (a structured binding: lambdas may not capture it before C++20 in clang 14)
  auto lower = [&](PointId v) { return costs ? costs[static_cast<std::size_t>(v)] : BoundCost(v, target); };
  // Ties to the entry furthest along (on a grid many routes cost the same: without this the
  // search would sweep all of them).
  auto later = [](const OpenItem& a, const OpenItem& b) { return a.key != b.key ? a.key > b.key : a.h < b.h; };
  auto relax = [&](PointId v, double d) {
    const auto i = static_cast<std::size_t>(v);
    if (seen[i] == stamp && dist[i] <= d) return;
    const double key = d + bound_scale * lower(v);
    if (!(key <= limit)) return;  // also unreachable (+infinity)
    seen[i] = stamp;
    dist[i] = d;
    heap.push_back({key, v, d});
    std::push_heap(heap.begin(), heap.end(), later);
  };
  relax(from, 0.0);
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), later);
    const OpenItem item = heap.back();
    heap.pop_back();
    const PointId u = item.point;
    const auto ui = static_cast<std::size_t>(u);
    if (item.h > dist[ui]) continue;  // stale entry
    if (u == to) return dist[ui];
    for (std::uint32_t k = search_begin[ui]; k < search_begin[ui + 1]; ++k) {
      const SearchArc& a = search_arcs[k];
      if (Allowed(a, q)) relax(a.to, item.h + a.time);
    }
  }
  return inf;
}

// Search: Route without the memo.
Detour TrafficController::Impl::Search(const traffic_detail::RouteQuery& q) {
  const auto [from, to, ban_point, ban_corridor, ban_guard, bound, keep_off] = q;
  (void)keep_off;  // read by Allowed(q)
  Detour out;
  if (to == ban_point || from == to) {
    if (from == to) out = {{from}, 0.0};
    return out;
  }
  // With a route bound (SetRouteBound): first the cheapest cost C (CheapestCost), then this
  // search without the points from which even the unobstructed route cannot arrive by C. No
  // cheapest route passes through one (with h* the table's bound, g + h* <= C on such a
  // route), nor does any of them reach a point of one at its cheapest cost first, so the
  // search finds the route it finds without the skip, having popped the same points before.
  double prune = std::numeric_limits<double>::infinity();
  if (bound_routes) {
    const double cheapest = CheapestCost(q);
    if (!std::isfinite(cheapest)) return out;  // nothing within the bound
    prune = cheapest + 1e-6 * (1.0 + cheapest);  // the margin covers float tables' rounding
  }
  // A min-heap on (key, point), as std::priority_queue<std::pair<double, PointId>> would
  // keep it, in a buffer kept between searches.
  std::vector<OpenItem>& heap = open;
  heap.clear();
  auto later = [](const OpenItem& a, const OpenItem& b) {
    return a.key != b.key ? a.key > b.key : a.point > b.point;
  };
  const Eigen::Vector2d goal = point_xy[static_cast<std::size_t>(to)];
  auto h = [&](PointId v) { return (point_xy[static_cast<std::size_t>(v)] - goal).norm() / config.speed; };
  const RouteTable* table = bound_routes.get();
  const double* costs = table ? table->CostsTo(to) : nullptr;  // read in place when the table allows
  const PointId target = to;  // (see CheapestCost)
  auto lower = [&](PointId v) { return costs ? costs[static_cast<std::size_t>(v)] : BoundCost(v, target); };
  if (++stamp == 0) {
    std::fill(seen.begin(), seen.end(), 0);
    stamp = 1;
  }
  auto relax = [&](PointId v, double d, ArcId a) {
    const auto i = static_cast<std::size_t>(v);
    if (seen[i] == stamp && dist[i] <= d) return;
    if (table && d + bound_scale * lower(v) > prune) return;
    seen[i] = stamp;
    dist[i] = d;
    via[i] = a;
    const double hv = h(v);
    heap.push_back({d + hv, v, hv});
    std::push_heap(heap.begin(), heap.end(), later);
  };
  relax(from, 0.0, -1);
  bool found = false;
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), later);
    const OpenItem item = heap.back();
    heap.pop_back();
    const double key = item.key;
    const PointId u = item.point;
    const double d = dist[static_cast<std::size_t>(u)];
    if (key > d + item.h + 1e-12) continue;  // stale entry
    if (key > bound) break;
    if (u == to) {
      found = true;
      break;
    }
    const auto ui = static_cast<std::size_t>(u);
    for (std::uint32_t k = search_begin[ui]; k < search_begin[ui + 1]; ++k) {
      const SearchArc& a = search_arcs[k];
      if (Allowed(a, q)) relax(a.to, d + a.time, a.arc);
    }
  }
  const auto ti = static_cast<std::size_t>(to);
  if (!found) return out;
  out.cost = dist[ti];
  for (PointId v = to; v != from; v = M().arc(via[static_cast<std::size_t>(v)]).from) {
    out.points.push_back(v);
  }
  out.points.push_back(from);
  std::reverse(out.points.begin(), out.points.end());
  return out;
}

// A new route must not start against robots holding a corridor the other way (a robot
// inside a corridor cannot turn back through its followers).

}  // namespace dispatch::engine
