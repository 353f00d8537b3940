// TrafficController: Wang2019 §3.3 case ② (TrafficControllerConfig::head_on_give_way). Of two
// robots meeting head-on where one stands waiting, "if the moving robot has the higher
// priority it passes normally, and the waiting robot drives to the next free node to wait
// there" (seed 004 §3.3 ②). Here: a robot w waits for robot h, and each one's route ahead
// runs through where the other stands (HeadOnPair). When h waits too (on w: a wait-for cycle,
// or on a third robot), has the lower priority and is not at work, h drives to the nearest
// free point off w's way (GiveWay: w's remaining route and the points within clearance of it)
// and waits there while its route ahead runs into w's way (at most T_w1 once there), then
// drives on. It gives way to the same robot again only after blocked_after. Off by default:
// measured (README, Traffic control) it helps formations on the dense grids and costs single
// orders there. The shared state is in traffic_controller_impl.h.
#include <algorithm>
#include <vector>

#include "engine/traffic/traffic_controller_impl.h"

namespace dispatch::engine {
namespace {

// Points of a route ahead looked at for a head-on (a corridor's length on the Chu2024 floor).
constexpr std::size_t kHeadOnLookahead = 16;
// Free points off the other robot's way tried as places to wait, nearest first, and the points
// searched for them.
constexpr std::size_t kGiveWayCandidates = 4;
constexpr std::size_t kGiveWaySearch = 64;

bool AheadOn(const ControlledRobot& x, PointId p) {
  for (std::size_t k = x.pos + 1; k < x.route.size() && k <= x.pos + kHeadOnLookahead; ++k) {
    if (x.route[k] == p) return true;
  }
  return false;
}

}  // namespace

bool TrafficController::Impl::HeadOnPair(std::size_t w, std::size_t h) const {
  const ControlledRobot& a = robots[w];
  const ControlledRobot& b = robots[h];
  return !a.removed && !b.removed && AheadOn(a, b.at) && AheadOn(b, a.at);
}

bool TrafficController::Impl::OnWayOf(std::size_t w, PointId p, double clearance) const {
  const ControlledRobot& y = robots[w];
  for (std::size_t k = y.pos; k < y.route.size(); ++k) {
    const PointId q = y.route[k];
    if (q == p) return true;
    for (const auto& [n, d] : near[static_cast<std::size_t>(q)]) {
      if (n == p && d < clearance) return true;
    }
  }
  return false;
}

bool TrafficController::Impl::MayGiveWay(std::size_t h, std::size_t w, double t) const {
  const ControlledRobot& x = robots[h];
  if (x.gave_way_to == static_cast<int>(w) && t - x.gave_way_at < config.blocked_after) return false;
  // Not to a robot that waited blocked_after: it was reported blocked, its orders went back, and
  // its wait says nothing about where it will drive (on a dense grid a robot gave way to a
  // blocked one, came back and gave way again, all run long).
  const ControlledRobot& y = robots[w];
  if (y.wait != WaitKind::kNone && t - y.wait_start >= config.blocked_after) return false;
  return config.head_on_give_way && x.wait != WaitKind::kNone && !x.working && x.next == kNoPoint &&
         x.pos + 1 < x.route.size() && x.group == 0 && x.envelope == 0.0 && Lower(h, w) && HeadOnPair(w, h);
}

bool TrafficController::Impl::GiveWay(std::size_t h, std::size_t w, double t) {
  ControlledRobot& x = robots[h];
  const double clearance = config.point_clearance + robots[w].envelope;
  // Breadth-first over free points, never into an intersection (but within the one it stands
  // in) nor against a corridor's holders; the first free points off w's way, with the way
  // there. Route (below) reuses the scratch arrays: the ways are copied out first.
  if (++stamp == 0) {
    std::fill(seen.begin(), seen.end(), 0);
    stamp = 1;
  }
  std::vector<std::vector<PointId>> ways;
  std::vector<PointId> frontier{x.at};
  seen[static_cast<std::size_t>(x.at)] = stamp;
  const int inside = M().IntersectionOf(x.at);
  for (std::size_t head = 0; head < frontier.size() && frontier.size() < kGiveWaySearch && ways.size() < kGiveWayCandidates;
       ++head) {
    const PointId u = frontier[head];
    for (ArcId a : M().out_arcs(u)) {
      const PointId v = M().arc(a).to;
      const auto vi = static_cast<std::size_t>(v);
      if (seen[vi] == stamp || PointBlocker(v, h) >= 0) continue;
      const int g = M().IntersectionOf(v);
      if (g >= 0 && g != inside) continue;
      const int c = CorridorOf(a);
      if (c >= 0 && CorridorBlocker(c, lanes.Direction(M(), a), h) >= 0) continue;
      seen[vi] = stamp;
      via[vi] = a;
      frontier.push_back(v);
      if (OnWayOf(w, v, clearance)) continue;
      std::vector<PointId> way{v};
      for (PointId p = v; p != x.at;) {
        p = M().arc(via[static_cast<std::size_t>(p)]).from;
        way.push_back(p);
      }
      ways.emplace_back(way.rbegin(), way.rend());
      if (ways.size() >= kGiveWayCandidates) break;
    }
  }
  const PointId goal = x.route.back();
  const double bound = RouteCost(x) + config.blocked_after;
  for (std::vector<PointId>& way : ways) {
    double drive = 0.0;  // to the point it waits at
    for (std::size_t k = 0; k + 1 < way.size(); ++k) drive += ArcTime(*M().FindArc(way[k], way[k + 1]));
    Detour on = Route(way.back(), goal, kNoPoint, -1, -1, bound);
    if (on.points.empty()) continue;
    way.insert(way.end(), on.points.begin() + 1, on.points.end());
    if (!StartAllowed(h, way) || !Assign(h, std::move(way)).ok()) continue;
    Replanned(x);
    ClearWait(x);
    x.give_way_to = static_cast<int>(w);
    x.give_way_until = t + drive + config.t_w1;
    x.gave_way_to = static_cast<int>(w);
    x.gave_way_at = t;
    ++stats.give_ways;
    return true;
  }
  return false;
}

int TrafficController::Impl::GivingWayTo(std::size_t r, double t) {
  ControlledRobot& x = robots[r];
  if (x.give_way_to < 0) return -1;
  const auto w = static_cast<std::size_t>(x.give_way_to);
  const double clearance = config.point_clearance + robots[w].envelope + x.envelope;
  if (t >= x.give_way_until || robots[w].removed) {
    x.give_way_to = -1;
    return -1;
  }
  // On its way off w's way it drives on (through points of w's way); off it, it stays while
  // its route ahead still runs into w's way.
  if (OnWayOf(w, x.at, clearance)) return -1;
  bool crossing = false;
  for (std::size_t k = x.pos + 1; k < x.route.size() && k <= x.pos + kHeadOnLookahead && !crossing; ++k) {
    crossing = OnWayOf(w, x.route[k], clearance);
  }
  if (!crossing) {  // w has passed
    x.give_way_to = -1;
    return -1;
  }
  // Waiting off w's way it holds no corridor it does not stand in: its last Go reserved the
  // corridors of the next two arcs, and w's way may run through them.
  corridor_scratch = x.corridors;
  for (int c : corridor_scratch) {
    if (lanes.interior_of[static_cast<std::size_t>(x.at)] != c) DropCorridor(c, r);
  }
  return x.give_way_to;
}

}  // namespace dispatch::engine
