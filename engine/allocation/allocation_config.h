// Settings of the allocation strategies (SPEC §3.2, Chu2024 §2): the bid weights of eqs.
// (1)-(5), the sampling step h of eq. (6), the robot speed v of eq. (3), the work time t_w,
// and the settings of the components the allocator drives (traffic prediction, formations).
//
// Defaults and why:
//  - alpha = beta = 0.5: the paper's values (seed 000 §4.2, "权重设定为 0.5").
//  - zeta = 100: the paper's traffic weight (seed 000 §4.2, Table 4). zeta = 0 gives the
//    plain auction of eq. (1).
//  - sample_step h = 0.5 m: the paper gives no value. Half a metre is a little more than one
//    robot diameter (0.4 m), so no zone crossed by a route is skipped on the Chu2024 floor
//    (its narrowest zone is metres wide), and at v = 1 m/s consecutive samples are 0.5 s
//    apart, the traffic predictor's default time bucket.
//  - speed v = 1 m/s: the paper gives no value; typical for warehouse robots. It must equal
//    the RouteTable's speed (RouteTableOptions::speed), because T_d is read off the table's
//    travel-time costs (Floyd distances / v).
//  - hold_seconds = 300 s: the traffic predictor sees nothing of a plan after its end, but a
//    robot does not vanish when its queue is done: it stands where its plan ends (an idle
//    robot at its parking station). FleetState publishes each plan to the predictor with a
//    final wait of hold_seconds there. 300 s is longer than any Chu2024 task (< 100 s), so
//    robots stay visible over a batch; 0 disables it.
//  - price_every_bid_up_to = 64 robots: in fleets up to this size every robot's F_i is
//    evaluated, so an award explains every bid in full (the paper's Tables 3 and 4). In
//    larger fleets the auction prices robots in order of alpha T_t + beta T_d (a lower bound
//    of B_i, since x_i >= 0) and stops once that bound exceeds the bids that decide the award
//    (winner and runner-up; for formations the companions and the next one): the same award,
//    without sampling routes that could not win.
//  - max_queue = 0: no limit, as in the paper. With a limit, orders wait (accepted) until a
//    robot has room, so a formation gets members that are nearly free instead of members
//    that reach its rendezvous one by one behind long queues (the service froze with seed
//    Tables 1 and 2 submitted ten times at once; README "Formations on the dispatch core").
//  - planner = rules: each award's route is the route table's (Chu2024 §3.1) and conflicts are
//    left to the traffic controller as they come. time_windows: each single-robot award is
//    re-planned through the free time windows of every other robot's plan (Wang2019 §2-3,
//    engine/planning/window_planner.h) with `windows` (its speed is `speed`); formations keep
//    the route table's routes and are reserved as they are.
//  - routing = floyd: the rules planner's routes are the route table's. heat: each single-robot
//    award's legs are routed again by Wang2019's heat-weighted Dijkstra over the lanes the
//    round's plans use in the next heat_period = 60 s (the seed leaves δ open; a minute spans a
//    few tasks on the Chu2024 floor). The bids price those routes: before its auction a round
//    prices T_d and samples the traffic prediction along the heat-weighted routes of the plans
//    it starts with (UseHeatRoutes, engine/dispatch/heat_awards.h). The time-window planners
//    keep their own routes and the table's bids.
//  - work_time_override: unset = every order's own t_w (Order::work_time, 5 s by default,
//    see kDefaultWorkTime); set = one t_w for every order, as in the paper.
// Plain value; validate with ValidateAllocationConfig. Thread-safe to share.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "engine/allocation/traffic_prediction.h"
#include "engine/common/result.h"
#include "engine/fleet/formation.h"
#include "engine/planning/time_windows.h"

namespace dispatch::engine {

// How an award's robots get their routes (issue 16 §3).
enum class PlannerKind { kRules, kTimeWindows, kConflictElimination };
// Which routes the rules planner gives them: the route table's shortest (Floyd, or its lazy
// equivalent on large floors) or Wang2019's heat-weighted ones (engine/planning/path_heat.h).
enum class RoutingKind { kFloyd, kHeat };

struct AllocationConfig {
  double alpha = 0.5;        // weight of T_t, total time (Chu2024 eq. (1))
  double beta = 0.5;         // weight of T_d, travel time (Chu2024 eq. (1))
  double zeta = 100.0;       // weight of the flow F (Chu2024 eq. (5)); >= 0
  double sample_step = 0.5;  // h, metres between route samples (Chu2024 eq. (6))
  double speed = 1.0;        // v, m/s (Chu2024 eq. (3))
  double hold_seconds = 300.0;  // predicted stay at a plan's end, seconds; >= 0
  std::size_t price_every_bid_up_to = 64;  // robots; larger fleets skip bids that cannot win
  std::optional<double> work_time_override;  // t_w for every order, seconds; unset = per order
  // Seconds a robot works at an order's drop. Unset (default): the order's t_w (or the
  // override), as at a pick: a drop takes as long as a pick. 0: the seed's model, where eq.
  // (3)'s n_c counts the pick points only and nothing is worked at the drop
  // (engine/fleet/plan.h says why).
  std::optional<double> drop_time;
  // Orders a robot may hold (its current one included) and still bid for another; 0 = no
  // limit (the paper's auction: every order is awarded at once, queues grow without bound).
  std::size_t max_queue = 0;
  // A robot joins a formation order (as its leader or a companion) only while its queue holds
  // fewer than this many orders; 0 = no limit (Chu2024 §2.2 as printed: the cheapest three,
  // whatever they still have to do). 1: only robots with nothing queued, so a team gathers at
  // once instead of holding its rendezvous while members finish queues of other work; the
  // product's default (dispatchd, dispatch-sim stream|compare; README "Formations on the
  // dispatch core"), 0 here so that the engine reproduces the paper. Single-robot orders are
  // not limited by it.
  std::size_t formation_max_queue = 0;
  TrafficPredictionConfig traffic;
  FormationOptions formation;
  // Turning time t_c (Wang2019 §2.2), seconds per 90 degrees of heading change; >= 0. It
  // enters plan ETAs (BuildPlan), the route table's costs and so T_d when the table is built
  // with it (RouteTableOptions::turn_penalty_s, the callers' part), the time-window planner,
  // and the simulator's robots. 0 (default): Chu2024 has no turning time.
  double turn_time = 0.0;
  PlannerKind planner = PlannerKind::kRules;
  // Planners kTimeWindows and kConflictElimination; its speed and turning time are replaced by
  // `speed` and `turn_time`.
  TimeWindowRules windows;
  RoutingKind routing = RoutingKind::kFloyd;
  double heat_period = 60.0;  // δ of Wang2019's path heat, seconds (> 0)
};

// "rules", "time-windows", "conflict-elimination" (PlannerNames: in the order help texts list
// them).
const char* PlannerName(PlannerKind planner);
std::optional<PlannerKind> ParsePlanner(std::string_view name);
std::vector<std::string> PlannerNames();
// "floyd", "heat".
const char* RoutingName(RoutingKind routing);
std::optional<RoutingKind> ParseRouting(std::string_view name);
std::vector<std::string> RoutingNames();

// kInvalidArgument naming the field: weights must be finite and >= 0, h and v finite and > 0,
// a work-time override finite and >= 0.
Status ValidateAllocationConfig(const AllocationConfig& config);

}  // namespace dispatch::engine
