// The head-on conflict of Wang2019 §4.3 (Table 6) on a small bidirectional-lane floor, run on
// the dispatch core (SimulateOnCore, the service's allocation rounds and traffic gate) with the
// "wait only", "re-plan" and "choose the faster" policies of the traffic controller.
//
// Floor (metres; every path a bidirectional single lane):
//   S0 (14,-3) - S1 (14,0) - B (14,2) - c3..c7 (14,3..7) - T (14,8) - U (14,10) - P (14,11)
//   T - V (16,8) [drop]    B - X (16,2) [drop]    c5 (14,5) and U are pick points
//   detour: B - D1 (7,2) 7 m, D1 - D2 (7,8) 6 m, D2 - T 7 m
// h1 (higher priority: it works first in the corridor) starts at S1, picks at c5 for
// `h1_work` seconds, drops at V. h2 waits at its park P, is released at 9 s, picks at U (1 s)
// and drops at X: its direct route runs down the corridor against h1, its detour is 14 m
// (14 s) longer - the paper's "re-planning costs 14 s more than no conflict". The auction
// awards the orders so (h1 is the nearer to c5; h2 stands next to U). With h1_work = 30 s the
// wait is ~24 s (the paper's h2 waited 30 s): re-planning is faster; with h1_work = 5 s
// waiting is. T_w1 is lifted so that "wait only" really only waits. (h2 parks at P rather
// than on the pick point U: an idle robot on a pick point is sent aside by the gate.)
// Pure functions; thread-safe.
#pragma once

#include <string>

#include "engine/common/result.h"

namespace dispatch::engine {

struct HeadOnRun {
  double h2_time = 0.0;   // h2's order: completion - release, s
  double h1_time = 0.0;   // h1's order: completion - release, s
  bool replanned = false; // h2's head-on decision
  double wait_estimate = 0.0, replan_extra = 0.0;
};

struct HeadOnComparison {
  double h1_work = 0.0;
  HeadOnRun wait, replan, chosen;  // kAlwaysWait, kAlwaysReplan, kChooseFaster
};

Result<HeadOnComparison> RunHeadOnComparison(double h1_work);

// Case ① of §3.3 on the same floor: h1 (task released first: the higher priority, with
// TrafficControllerConfig::priority_by_release; both loaded, one class) picks at S0 where it
// stands for 1 s, then drives north through the corridor to drop at V; h2 (released 0.5 s
// later) picks at U for 1 s and drives south through it to drop at X. h2 reaches the free
// corridor first, while h1 is still on its way to the other end: first come
// (head_on_priority off) h2 enters and h1 waits at the corridor's end; with head_on_priority
// h2 gives way (it waits: the detour is 14 s longer) and h1 passes. Times are completion -
// release of each order.
struct CaseOneRun {
  double h1_time = 0.0, h2_time = 0.0;
  bool h1_met_head_on = false, h2_met_head_on = false;  // each one's head-on decisions (HeadOnRecord)
  std::size_t deadlocks = 0;
};
struct CaseOneComparison {
  CaseOneRun first_come, priority;
};
Result<CaseOneComparison> RunCaseOneComparison();

}  // namespace dispatch::engine
