// Wang2019's time-window model (seed 004 §2.3, eqs. (1)-(2), (7)-(11)) in continuous time on
// the map's graph: every robot's timed route reserves a window at each point it passes and on
// each lane it drives, and a route may only use the free windows the others leave.
//
//   A visit of point p, arriving at a and leaving at d, holds p over [a, d + clear]: clear is
//   the time to put the safe distance between a robot and the point it left (assumption 3:
//   body length + the distance driven in `headway_s` seconds, at the cruise speed). Two
//   robots' windows at one point never overlap, so a follower keeps the safe distance.
//   Driving arc j -> k from d to a' holds the lane over [d, a'] in that direction. On a
//   bidirectional single lane the two directions' windows never overlap (eq. (11)), and one
//   direction holds at most floor(L_jk / L_v) robots at once (eq. (10)).
// A route's last visit may last for ever (depart = +infinity): the robot stays there.
//
// Plain values; ReservationTable is not thread-safe to mutate, safe to read concurrently.
#pragma once

#include <limits>
#include <memory>
#include <optional>
#include <unordered_map>
#include <utility>
#include <vector>

#include "engine/common/result.h"
#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

inline constexpr double kForever = std::numeric_limits<double>::infinity();

struct TimeWindowRules {
  double speed = 1.0;          // cruise speed, m/s (an arc's own max_speed caps it)
  double body_length = 0.5;    // L_v, m
  double headway_s = 0.5;      // t of the safe distance body_length + speed * t
  double turn_s_per_90 = 0.0;  // turning time per 90 degrees of heading change (0: none)

  // Seconds a point stays held after a robot leaves it.
  double ClearTime() const { return body_length / speed + headway_s; }
  Status Validate() const;
};

struct TimedVisit {
  PointId point = kNoPoint;
  double arrive = 0.0;
  double depart = 0.0;  // >= arrive; kForever: it stays
};
// Consecutive visits are joined by an arc of the map, driven from one's depart to the next's
// arrive.
using TimedRoute = std::vector<TimedVisit>;

struct TimeWindow {
  double from = 0.0;
  double to = 0.0;
  int robot = -1;
};

// Seconds to drive arc `a` at the rules' speed (capped by the arc's own), and to turn from
// arc `before` into arc `a` at their shared point (0 without a turning time or a `before`).
double DriveTime(const WarehouseMap& map, const TimeWindowRules& rules, ArcId a);
double TurnTime(const WarehouseMap& map, const TimeWindowRules& rules, ArcId before, ArcId a);

class ReservationTable {
 public:
  ReservationTable(std::shared_ptr<const WarehouseMap> map, TimeWindowRules rules);

  const WarehouseMap& map() const { return *map_; }
  const TimeWindowRules& rules() const { return rules_; }

  // Reserves robot's route (replacing any it held). Errors: a point that is none, two
  // consecutive visits not joined by an arc, times out of order or faster than the arc
  // allows. It does not check the route against others (CheckTimeWindows does).
  Status Reserve(int robot, const TimedRoute& route);
  void Release(int robot);
  const TimedRoute* RouteOf(int robot) const;

  // The windows held at point p / on arc a (in its direction), sorted by start.
  const std::vector<TimeWindow>& PointWindows(PointId p) const { return points_[static_cast<std::size_t>(p)]; }
  const std::vector<TimeWindow>& ArcWindows(ArcId a) const { return arcs_[static_cast<std::size_t>(a)]; }
  // The free intervals at p for `robot` (others' windows merged and complemented), sorted;
  // the last one ends at kForever unless someone stays there for ever.
  std::vector<std::pair<double, double>> FreeIntervals(PointId p, int robot) const;
  // Robots on arc a (its direction) at some moment of [from, to], and whether the opposite
  // direction of its lane is held then, `robot` excepted.
  int SameDirectionDuring(ArcId a, double from, double to, int robot) const;
  // The earliest t >= from at which [t, t + length] meets no window of the opposite
  // direction of a's lane (from itself for a one-way arc).
  double OppositeFreeFrom(ArcId a, double from, double length, int robot) const;

 private:
  static void Insert(std::vector<TimeWindow>& windows, TimeWindow w);
  // The first of arc a's windows that may reach past t (by its longest window), for scans.
  std::vector<TimeWindow>::const_iterator FirstReaching(ArcId a, double t) const;
  static void Erase(std::vector<TimeWindow>& windows, int robot);

  std::shared_ptr<const WarehouseMap> map_;
  TimeWindowRules rules_;
  std::vector<std::vector<TimeWindow>> points_;
  std::vector<std::vector<TimeWindow>> arcs_;
  std::vector<double> arc_longest_;  // per arc: no window on it ever lasted longer
  std::unordered_map<int, TimedRoute> routes_;
};

// The checker of the model above: each route well formed (as Reserve), no two robots'
// windows overlapping at a point, opposite directions of a lane never at once, no lane over
// its capacity. Errors name the first fault (robots by index).
Status CheckTimeWindows(const WarehouseMap& map, const TimeWindowRules& rules, const std::vector<TimedRoute>& routes);

// The earliest conflict between two robots in `table` (BIT2024 step 7's "first conflict", in
// continuous time): two windows at one point that overlap, or one lane driven both ways at
// once; by the time they begin to overlap, ties by point then arc order. Lane capacity
// (eq. (10)) is not looked at. Each robot's window is given, so a planner can keep one robot's
// and forbid it to the other.
struct WindowConflict {
  PointId point = kNoPoint;  // a point conflict, else kNoPoint
  ArcId arc = -1;            // a lane conflict: robot a drives `arc`, robot b its reverse
  TimeWindow a, b;           // the two robots' windows (a.robot < b.robot for points)
  double at = 0.0;           // when they begin to overlap
};
std::optional<WindowConflict> EarliestConflict(const ReservationTable& table);

// Seconds from the route's first arrival to its last arrival (its makespan), 0 for none.
double RouteDuration(const TimedRoute& route);

}  // namespace dispatch::engine
