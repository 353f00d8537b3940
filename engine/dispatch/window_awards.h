// The time-window planner in an allocation round (issue 16 §3, AllocationConfig::planner =
// time-windows): after the strategy has awarded the round's orders, each single-robot award's
// new segment is planned again through the free time windows of every other robot's plan
// (Wang2019 §2-3; engine/planning/window_planner.h), awards in allocation order (the seed's
// rule: earlier release first), each reserving its route for the next. Formation awards keep
// their route-table routes and are reserved as they are; so are robots that win a formation in
// the round, and a four-wheel-steer robot's segments refined through free space (their posed
// waypoints are named after the graph points they pass, so their windows are those points'
// and arcs').
//
// A plan's last visit is held for ever, but at a pick or drop only 5 s after the work there (an
// idle robot by a service point steps aside at once: TrafficGate); held for ever, it left every
// later award with a stop there unplanned (on the dense grids half of the time windows' awards).
//
// A re-planned segment keeps its stops, actions and work times; its waits become departures:
// a robot reaching a waypoint ahead of plan waits for its planned departure (the robots'
// rule, WaypointRobot and fleet-sim), so a move waypoint where it must wait carries the end of
// the wait as its eta, and a stop the end of its work less the work time. When the planner
// finds no route (a stop held for ever, say by a robot parked on it), the segment stays as
// the strategy planned it and a note says why; the traffic controller stays the safety net.
//
// Pure; the caller's FleetState is read, the awards rewritten. Both planners below.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "engine/allocation/allocation_config.h"
#include "engine/allocation/fleet_state.h"
#include "engine/dispatch/allocation_round.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine {

// Per robot of `fleet` (its index): where this round's new waypoints begin in its plan
// (kNothingNew: it won nothing), and whether it won a formation in the round.
struct RoundSegments {
  static constexpr std::size_t kNothingNew = static_cast<std::size_t>(-1);
  std::vector<std::size_t> first_new;
  std::vector<bool> in_formation;
};

void PlanAwardsInWindows(const std::shared_ptr<const WarehouseMap>& map, const RouteTable& routes,
                         const AllocationConfig& config,
                         const FleetState& fleet, const RoundSegments& segments, double now,
                         std::vector<RoundAward>& awards, std::vector<std::string>& notes);

// BIT2024 step 7 (seed 003 s71-s73) in the same time windows (AllocationConfig::planner =
// conflict-elimination): every re-planned robot's new segments are first planned alone,
// through the windows of the plans kept from before the round only (not through each
// other's); then, at the first conflict among them (EarliestConflict: two windows at a point,
// a lane both ways), one of the two robots keeps its route (a seeded random choice) and the
// other is kept out of that robot's window there (a constraint: a pseudo reservation only its
// own searches see) and planned again; until none is left. Deterministic (the seed comes from
// the round's time) and bounded by 8 iterations per robot + 8 (a replay re-runs the same
// round; a wall-clock deadline would not); conflicts left then, or between robots whose
// constraints leave no route, are the traffic controller's, as with every planner.
void PlanAwardsByConflictElimination(const std::shared_ptr<const WarehouseMap>& map, const RouteTable& routes,
                                     const AllocationConfig& config, const FleetState& fleet,
                                     const RoundSegments& segments, double now, std::vector<RoundAward>& awards,
                                     std::vector<std::string>& notes);

}  // namespace dispatch::engine
