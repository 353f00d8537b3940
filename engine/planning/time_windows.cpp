#include "engine/planning/time_windows.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "engine/common/numbers.h"
#include "engine/routing/cost_graph.h"

namespace dispatch::engine {
namespace {

bool Overlap(double a_from, double a_to, double b_from, double b_to) {
  return a_from < b_to - kEps && b_from < a_to - kEps;
}

std::string Time(double t) { return std::isinf(t) ? std::string("for ever") : std::to_string(t); }

// The route's faults on its own (as Reserve states them), or Ok.
Status CheckRoute(const WarehouseMap& map, const TimeWindowRules& rules, const TimedRoute& route) {
  for (std::size_t i = 0; i < route.size(); ++i) {
    const TimedVisit& v = route[i];
    const std::string at = "visit " + std::to_string(i);
    if (v.point < 0 || static_cast<std::size_t>(v.point) >= map.point_count()) {
      return InvalidArgument(at + ": point " + std::to_string(v.point) + " is not on the map");
    }
    if (!(v.depart >= v.arrive) || std::isnan(v.arrive) || std::isinf(v.arrive)) {
      return InvalidArgument(at + ": departs at " + Time(v.depart) + " before it arrives at " + Time(v.arrive));
    }
    if (std::isinf(v.depart) && i + 1 != route.size()) return InvalidArgument(at + ": stays for ever but is not the last");
    if (i == 0) continue;
    const auto arc = map.FindArc(route[i - 1].point, v.point);
    if (!arc) {
      return InvalidArgument(at + ": no arc from point " + std::to_string(route[i - 1].point) + " to " +
                             std::to_string(v.point));
    }
    if (v.arrive + 1e-6 < route[i - 1].depart + DriveTime(map, rules, *arc)) {
      return InvalidArgument(at + ": arrives at " + Time(v.arrive) + ", faster than the arc allows");
    }
  }
  return Ok{};
}

}  // namespace

Status TimeWindowRules::Validate() const {
  if (!(speed > 0.0) || !(body_length > 0.0) || !(headway_s >= 0.0) || !(turn_s_per_90 >= 0.0) ||
      std::isinf(speed) || std::isinf(body_length) || std::isinf(headway_s) || std::isinf(turn_s_per_90)) {
    return InvalidArgument("time windows: speed and body length must be > 0, headway and turning time >= 0");
  }
  return Ok{};
}

double DriveTime(const WarehouseMap& map, const TimeWindowRules& rules, ArcId a) {
  const Arc& arc = map.arc(a);
  const double v = arc.max_speed > 0.0 ? std::min(rules.speed, arc.max_speed) : rules.speed;
  return arc.length / v;
}

double TurnTime(const WarehouseMap& map, const TimeWindowRules& rules, ArcId before, ArcId a) {
  if (before < 0 || rules.turn_s_per_90 <= 0.0) return 0.0;
  return rules.turn_s_per_90 * TurnAngle(map, before, a) / (std::numbers::pi / 2.0);
}

ReservationTable::ReservationTable(std::shared_ptr<const WarehouseMap> map, TimeWindowRules rules)
    : map_(std::move(map)),
      rules_(rules),
      points_(map_->point_count()),
      arcs_(map_->arcs().size()),
      arc_longest_(map_->arcs().size(), 0.0) {}

std::vector<TimeWindow>::const_iterator ReservationTable::FirstReaching(ArcId a, double t) const {
  const auto& w = arcs_[static_cast<std::size_t>(a)];
  const double from = t - arc_longest_[static_cast<std::size_t>(a)] - kEps;
  return std::lower_bound(w.begin(), w.end(), from, [](const TimeWindow& x, double v) { return x.from < v; });
}

void ReservationTable::Insert(std::vector<TimeWindow>& windows, TimeWindow w) {
  auto at = std::upper_bound(windows.begin(), windows.end(), w.from,
                             [](double t, const TimeWindow& x) { return t < x.from; });
  windows.insert(at, w);
}

void ReservationTable::Erase(std::vector<TimeWindow>& windows, int robot) {
  windows.erase(std::remove_if(windows.begin(), windows.end(), [&](const TimeWindow& w) { return w.robot == robot; }),
                windows.end());
}

Status ReservationTable::Reserve(int robot, const TimedRoute& route) {
  if (Status ok = CheckRoute(*map_, rules_, route); !ok.ok()) {
    return InvalidArgument("robot " + std::to_string(robot) + ": " + ok.error().message);
  }
  Release(robot);
  const double clear = rules_.ClearTime();
  for (std::size_t i = 0; i < route.size(); ++i) {
    const TimedVisit& v = route[i];
    Insert(points_[static_cast<std::size_t>(v.point)], {v.arrive, v.depart + clear, robot});
    if (i > 0) {
      const ArcId a = *map_->FindArc(route[i - 1].point, v.point);
      Insert(arcs_[static_cast<std::size_t>(a)], {route[i - 1].depart, v.arrive, robot});
      double& longest = arc_longest_[static_cast<std::size_t>(a)];
      longest = std::max(longest, v.arrive - route[i - 1].depart);
    }
  }
  routes_[robot] = route;
  return Ok{};
}

void ReservationTable::Release(int robot) {
  auto it = routes_.find(robot);
  if (it == routes_.end()) return;
  const TimedRoute& route = it->second;
  for (std::size_t i = 0; i < route.size(); ++i) {
    Erase(points_[static_cast<std::size_t>(route[i].point)], robot);
    if (i > 0) Erase(arcs_[static_cast<std::size_t>(*map_->FindArc(route[i - 1].point, route[i].point))], robot);
  }
  routes_.erase(it);
}

const TimedRoute* ReservationTable::RouteOf(int robot) const {
  auto it = routes_.find(robot);
  return it == routes_.end() ? nullptr : &it->second;
}

std::vector<std::pair<double, double>> ReservationTable::FreeIntervals(PointId p, int robot) const {
  std::vector<std::pair<double, double>> free;
  double start = -kForever;
  for (const TimeWindow& w : points_[static_cast<std::size_t>(p)]) {  // sorted by from
    if (w.robot == robot) continue;
    if (w.from > start + kEps) free.emplace_back(start, w.from);
    start = std::max(start, w.to);
  }
  if (start < kForever) free.emplace_back(start, kForever);
  return free;
}

int ReservationTable::SameDirectionDuring(ArcId a, double from, double to, int robot) const {
  int n = 0;
  const auto& windows = arcs_[static_cast<std::size_t>(a)];
  for (auto w = FirstReaching(a, from); w != windows.end() && w->from < to; ++w) {
    if (w->robot != robot && Overlap(w->from, w->to, from, to)) ++n;
  }
  return n;
}

double ReservationTable::OppositeFreeFrom(ArcId a, double from, double length, int robot) const {
  const ArcId back = map_->arc(a).reverse_arc;
  if (back < 0) return from;
  double t = from;
  const auto& windows = arcs_[static_cast<std::size_t>(back)];
  for (auto w = FirstReaching(back, from); w != windows.end(); ++w) {  // sorted by from
    if (w->robot == robot) continue;
    if (w->from >= t + length - kEps) break;
    if (Overlap(w->from, w->to, t, t + length)) t = w->to;
  }
  return t;
}

Status CheckTimeWindows(const WarehouseMap& map, const TimeWindowRules& rules, const std::vector<TimedRoute>& routes) {
  if (Status ok = rules.Validate(); !ok.ok()) return ok;
  ReservationTable table(std::shared_ptr<const WarehouseMap>(&map, [](const WarehouseMap*) {}), rules);
  for (std::size_t r = 0; r < routes.size(); ++r) {
    if (Status ok = table.Reserve(static_cast<int>(r), routes[r]); !ok.ok()) return ok;
  }
  auto who = [](int a, int b) { return "robots " + std::to_string(a) + " and " + std::to_string(b); };
  for (std::size_t p = 0; p < map.point_count(); ++p) {
    const auto& w = table.PointWindows(static_cast<PointId>(p));
    for (std::size_t i = 1; i < w.size(); ++i) {
      for (std::size_t j = 0; j < i; ++j) {
        if (w[j].robot != w[i].robot && Overlap(w[j].from, w[j].to, w[i].from, w[i].to)) {
          return InvalidArgument(who(w[j].robot, w[i].robot) + " hold point " + map.point(static_cast<PointId>(p)).name +
                                 " at once (from " + Time(w[i].from) + ")");
        }
      }
    }
  }
  for (std::size_t a = 0; a < map.arcs().size(); ++a) {
    const Arc& arc = map.arcs()[a];
    const auto& w = table.ArcWindows(static_cast<ArcId>(a));
    const int capacity = std::max(1, static_cast<int>(std::floor(arc.length / rules.body_length + 1e-9)));
    for (const TimeWindow& x : w) {
      if (table.SameDirectionDuring(static_cast<ArcId>(a), x.from, x.to, -1) > capacity) {
        return InvalidArgument("more than " + std::to_string(capacity) + " robots on the lane from " +
                               map.point(arc.from).name + " to " + map.point(arc.to).name + " at " + Time(x.from));
      }
      if (arc.reverse_arc >= 0) {
        for (const TimeWindow& y : table.ArcWindows(arc.reverse_arc)) {
          if (y.robot != x.robot && Overlap(x.from, x.to, y.from, y.to)) {
            return InvalidArgument(who(x.robot, y.robot) + " drive the lane between " + map.point(arc.from).name +
                                   " and " + map.point(arc.to).name + " in opposite directions at once (from " +
                                   Time(std::max(x.from, y.from)) + ")");
          }
        }
      }
    }
  }
  return Ok{};
}

std::optional<WindowConflict> EarliestConflict(const ReservationTable& table) {
  const WarehouseMap& map = table.map();
  std::optional<WindowConflict> best;
  auto offer = [&](WindowConflict c) {
    if (!best || c.at < best->at) best = c;
  };
  for (std::size_t p = 0; p < map.point_count(); ++p) {
    const auto& w = table.PointWindows(static_cast<PointId>(p));  // sorted by start
    for (std::size_t i = 1; i < w.size(); ++i) {
      for (std::size_t j = 0; j < i; ++j) {
        if (w[j].robot == w[i].robot || !Overlap(w[j].from, w[j].to, w[i].from, w[i].to)) continue;
        WindowConflict c;
        c.point = static_cast<PointId>(p);
        c.a = w[j].robot < w[i].robot ? w[j] : w[i];
        c.b = w[j].robot < w[i].robot ? w[i] : w[j];
        c.at = std::max(w[j].from, w[i].from);
        offer(c);
      }
    }
  }
  for (std::size_t a = 0; a < map.arcs().size(); ++a) {
    const Arc& arc = map.arcs()[a];
    if (arc.reverse_arc < 0 || static_cast<std::size_t>(arc.reverse_arc) < a) continue;  // each lane once
    for (const TimeWindow& x : table.ArcWindows(static_cast<ArcId>(a))) {
      for (const TimeWindow& y : table.ArcWindows(arc.reverse_arc)) {
        if (y.robot == x.robot || !Overlap(x.from, x.to, y.from, y.to)) continue;
        WindowConflict c;
        c.arc = static_cast<ArcId>(a);
        c.a = x;
        c.b = y;
        c.at = std::max(x.from, y.from);
        offer(c);
      }
    }
  }
  return best;
}

double RouteDuration(const TimedRoute& route) {
  return route.empty() ? 0.0 : route.back().arrive - route.front().arrive;
}

}  // namespace dispatch::engine
