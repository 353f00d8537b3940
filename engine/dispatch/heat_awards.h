// Wang2019's path heat in an allocation round (issue 16 §1, AllocationConfig::routing = heat):
// after the strategy's awards, the lanes every robot's plan uses in the next heat_period give
// the heat (steps 1-4 of seed 004 §3.1; the new segments are the plain routes of step 1), and
// each single-robot award's legs between its stops are routed again over the heat-weighted
// lengths (step 5) and, with turn_time > 0, the turning time (the seed's improved Dijkstra,
// §4.1), timed at the allocation's speed with the turns and the stops' work times. Formation
// awards keep their routes (a member's next single-robot segment starts where its formation
// segment ends). Pure; the awards are rewritten.
//
// Before the auction (UseHeatRoutes) the round's fleet state takes a heat-weighted route table
// built from the plans the round starts with, so the bids price the routes the robots will
// drive (T_d, and the traffic prediction's samples along them): issue 16 §1, "usable by the
// auction's route costs".
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "engine/allocation/allocation_config.h"
#include "engine/allocation/fleet_state.h"
#include "engine/dispatch/allocation_round.h"
#include "engine/dispatch/window_awards.h"

namespace dispatch::engine {

// From now on `fleet` plans and prices with the heat-weighted routes (HeatRouteTable) of the
// lanes its plans use in [now, now + heat_period]; with no lane used it keeps its table.
// Errors: those of HeatRouteTable and FleetState::UseRoutes (the fleet then keeps its table).
Status UseHeatRoutes(std::shared_ptr<const WarehouseMap> map, const AllocationConfig& config, FleetState& fleet,
                     double now);

void RouteAwardsByHeat(const WarehouseMap& map, const AllocationConfig& config, const FleetState& fleet,
                       const RoundSegments& segments, double now, std::vector<RoundAward>& awards,
                       std::vector<std::string>& notes);

}  // namespace dispatch::engine
