// Order-stream simulation on the dispatch core (issue 15 §3): the service's DispatchCore
// (engine/dispatch/dispatch_core.h) - allocation rounds, awards, the TrafficGate with its
// formation teams, picks, drops, releases of blocked robots - driven in process by robots that
// follow its messages (WaypointRobot), on a fixed time step, deterministically. What a
// formation, a re-plan or a grant does here is what it does in dispatchd.
//
// Loop per step t (dt = time_step):
//  1. Orders whose release time (else created time) is <= t enter the core.
//  2. When the core says a round is due (an order arrived or came back, a robot finished an
//     order) - and, with allocation_period > 0, at most every allocation_period - one round of
//     the chosen strategy runs on the core's inputs and all its awards that still hold are
//     applied (the service commits them a few per loop turn; here at once).
//  3. Every robot advances to t and reports (arrivals, picks, drops, then a state report);
//     the core's changes are applied and its messages delivered at once (no network).
//  4. The gate steps (grants, holds, re-plans); a blocked robot gives its orders back (started
//     ones fail, the others are re-allocated) and stays where it stands, in fault, for
//     blocked_recovery seconds (CoreOptions::blocked_recovery; then it is idle again, listed in
//     StreamResult::recovered).
// Orders not finished by max_time fail ("not finished by ...").
//
// StreamResult: per order, the leader (robots[0] of the award), the team, completion time or
// failure; the gate's traffic statistics; total distance driven, robot-seconds waiting with a
// plan (not moving, not working), moving -> waiting transitions; overall_min_distance is the
// gate's (centre distance of robots of different agents, from the robots' positions at every
// step). With check_safety, CheckSafety over every step's true robot positions (not the gate's
// belief), a formation's members grouped as the gate groups them; record_frames keeps those
// frames.
//
// This is the product's only order-stream simulator: the older order-stream model, with its
// own motion and its own copy of the formation teams, is gone (issue 15 §3). The plan
// simulator (simulator.h) is a different thing: timed plans executed under the Chu2024 rules.
//
// Pure function of its inputs; thread-safe.
#pragma once

#include <memory>
#include <vector>

#include "engine/dispatch/core_journal.h"
#include "engine/dispatch/dispatch_core.h"
#include "engine/sim/stream_result.h"

namespace dispatch::engine {

// The core SimulateOnCore builds for `config` (its journal's setup records the same).
CoreOptions CoreOptionsOf(const StreamConfig& config);

// With `journal`, every call the run made on the core is journaled there (the service's format,
// engine/dispatch/core_journal.h): CoreReplay reproduces the run from it.
// Errors: bad config, null map/routes, no robots, robots that cannot
// be placed (unknown or shared start points), a formation order with fewer than 3 robots.
Result<StreamResult> SimulateOnCore(std::shared_ptr<const WarehouseMap> map, std::shared_ptr<const RouteTable> routes,
                                    const std::vector<FleetRobot>& robots, std::vector<Order> orders,
                                    const StreamConfig& config = {}, std::vector<JournalEntry>* journal = nullptr);

}  // namespace dispatch::engine
