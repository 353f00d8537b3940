// Wang2019's offline stage with time windows (seed 004 §2-3): a robot's route is the earliest
// arrival through the free windows the other robots' reservations leave (ReservationTable),
// waits included; robots are planned one after another in priority order (earlier task
// release first, a working robot before the rest: the seed's rule), each reserving its route
// for the next. The search is safe-interval path planning (Phillips & Likhachev 2011, SIPP):
// A* over (point, free interval of that point, arc it came by) with the earliest arrival in
// each, the route table's travel time to the goal as the heuristic.
//
// A request is a start (point, time) and stops, each with a work time (t_w) spent standing
// there; the robot stays at its last stop for ever unless `stay_at_end` is false. Stops are
// planned one after another, each at its earliest arrival (so a route is the earliest for
// each stop in turn, not always for the whole sequence).
// Pure; thread-safe for distinct tables.
#pragma once

#include <vector>

#include "engine/planning/plan_limits.h"
#include "engine/planning/time_windows.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine {

struct WindowStop {
  PointId point = kNoPoint;
  double work_s = 0.0;  // standing there before it may leave, >= 0
};

struct WindowRequest {
  int robot = -1;
  PointId start = kNoPoint;
  double start_time = 0.0;
  std::vector<WindowStop> stops;
  bool stay_at_end = true;
  double release_time = 0.0;  // priority: earlier first
  bool working = false;       // priority: before every robot that is not
};

struct WindowPlan {
  TimedRoute route;
  std::vector<std::size_t> stop_visits;  // per stop: the visit of the route where it works
  std::size_t expanded = 0;  // search states expanded, over all stops
};

// The earliest route for `request` through `table`'s free windows (the robot's own
// reservation ignored). `routes` gives the heuristic: its Cost at its own speed, so it is
// admissible when that speed is at least the rules' and its turn penalty at most theirs.
// Errors: kInvalidArgument (bad request), kUnreachable (no route through the windows, e.g.
// the start is held by another robot then, or a stop is never free long enough),
// kFailedPrecondition (stopped by `limits`; max_expansions bounds one stop's search).
Result<WindowPlan> PlanInWindows(const ReservationTable& table, const RouteTable& routes, const WindowRequest& request,
                                 const PlanLimits& limits = {});

struct PrioritizedPlans {
  std::vector<TimedRoute> routes;  // per request, in the requests' order (empty: failed)
  std::vector<Error> errors;       // per request: why it failed (its message empty if not)
  std::vector<std::size_t> order;  // the planning order (indices into the requests)
  std::size_t expanded = 0;
};

// Plans `requests` one by one in priority order into `table` (working first, then earlier
// release, then the request's index), reserving each route found. A request that fails is
// left unreserved and reported; the others go on. kFailedPrecondition when `limits.stop`
// fires (what was planned stays reserved).
Result<PrioritizedPlans> PlanInPriorityOrder(ReservationTable& table, const RouteTable& routes,
                                             const std::vector<WindowRequest>& requests, const PlanLimits& limits = {});

}  // namespace dispatch::engine
