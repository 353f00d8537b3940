// The improved hybrid A* of BIT2024 step 6 (SPEC §3.7) for four-wheel independent-steering
// (4WIS) robots in narrow areas: a search over continuous poses (x, y, theta), merged into
// cells of the occupancy grid and `heading_bins` heading bins, with the 4WIS motion modes as
// successors — straight forward / reverse, crab left / right, spin in place both ways, and
// the four steer arcs of the minimum turning radius.
//
// Cost (BIT2024 eq. (4)): g(s) = g(s_f) + dist(s_f, s) * (1 + lambda_turn * [s is reached on a
//   steer arc] + lambda_switch * [the move's DriveClass differs from the parent's]).
//   The seed writes both penalties as multiples of dist(s_f, s); we apply each only when its
//   condition holds (the seed's claim text: the turn penalty "when the robot is in the forward
//   left / right, backward left / right state", the switch penalty "when it switches between
//   straight, reverse, crab, spin and steer"). A switch is a change of DriveClass
//   (motion_path.h): steering on the move is priced by lambda_turn, not as a switch. For a
//   spin, dist = angle * spin_radius (metres swept at `spin_radius` from the centre). The
//   analytic tails below are priced the same way as if driven in search steps: a tail segment
//   pays the switch penalty on its first step only.
// Heuristic (eq. (5)): h = h_o + h_h, h_h = heading_weight * |theta_goal - theta|. h_o is the
//   Manhattan distance to the goal. With `manhattan_through_free_cells` (default) it is
//   measured through the grid: the 4-connected step count from the goal's cell over cells
//   where the robot's centre may stand (clearance >= half the footprint width less half a
//   cell), times the resolution — the same |dx| + |dy| where nothing is in the way, but it
//   sends the search around walls instead of into them (one breadth-first sweep per query).
//   Cells the sweep does not reach fall back to |dx| + |dy|. false: the seed's plain
//   |dx| + |dy|. Not admissible either way; the search is weighted anyway.
// Priority (eq. (6)): f = g + xi * h, xi by the Euclidean distance to the goal: the first band
//   whose `from` the distance reaches (bands sorted by `from` descending), so xi shrinks as the
//   robot nears the goal; `adaptive_xi = false` uses `fixed_xi` everywhere.
// Analytic expansion: at every expanded node closer than `analytic_range` to the goal, the
//   straight variant (the shortest Reeds-Shepp paths, up to `rs_candidates` of them) and the
//   crab variant (below) are built and collision-checked at `sample_spacing`; the cheaper
//   collision-free one by eq. (4) finishes the path. Crab variant: spin in place to the goal
//   heading (when it differs), then drive straight along it and crab across it (or crab first,
//   then straight: both orders tried), i.e. a Reeds-Shepp-like path whose curves are spins and
//   whose lateral leg is a crab. Needs allow_crab (and allow_spin when the heading differs).
// `allow_crab = false, allow_spin = false` is the baseline of issue 17 §2: the same search
// with forward, reverse and the four arcs only — a car that may reverse (a differential-drive
// robot would keep the spin: allow_spin = true alone).
// The search ends at the first node whose analytic expansion succeeds (or that lies within
// the goal tolerance): weighted and first-found, so paths are feasible, not optimal, and are
// not smoothed.
// Stops: PlanLimits::Exhausted is polled before each expansion (max_expansions counts them).
// Errors: kInvalidArgument (bad options, start or goal pose collides), kUnreachable (every
// reachable state expanded, no path), kFailedPrecondition (stopped by the limits: deadline or
// cancel — the code the other planners use for it). Deterministic: ties are broken by the
// order nodes were created. Pure; thread-safe for distinct calls (the checker is read-only).
#pragma once

#include <vector>

#include "engine/common/result.h"
#include "engine/motion/footprint.h"
#include "engine/motion/motion_path.h"
#include "engine/planning/plan_limits.h"

namespace dispatch::engine {

struct XiBand {
  double from = 0.0;  // metres to the goal at or beyond which this xi applies
  double xi = 1.0;
};

struct HybridAStarOptions {
  int heading_bins = 72;           // 5 degrees
  double step = 0.2;               // metres per straight, crab or arc successor
  double min_turn_radius = 0.8;    // metres
  int spin_bins = 3;               // heading bins per spin successor (15 degrees)
  double spin_radius = 0.3;        // metres: dist of a spin = angle * spin_radius
  bool allow_crab = true;
  bool allow_spin = true;
  double lambda_turn = 0.3;        // eq. (4)
  double lambda_switch = 5.0;      // eq. (4): at step 0.2 m a switch costs 1 m of travel
  double heading_weight = 0.3;     // eq. (5), metres per radian
  bool manhattan_through_free_cells = true;  // eq. (5) h_o, see above
  bool adaptive_xi = true;         // eq. (6)
  // Beyond 6 m 1.5, 3-6 m 1.2, within 3 m (the analytic range) 1.0. Steeper bands (up to 2.0)
  // made the search greedier into walls on the narrow floor (narrow_floor.md, measurements).
  std::vector<XiBand> xi_bands = {{6.0, 1.5}, {3.0, 1.2}, {0.0, 1.0}};
  double fixed_xi = 1.0;
  double analytic_range = 3.0;     // metres
  int rs_candidates = 4;
  double sample_spacing = 0.05;    // metres (radians / spin_radius for spins)
  double goal_xy_tolerance = 0.1;  // metres: a searched node this close ...
  double goal_theta_tolerance = 0.0873;  // ... and within this heading (5 deg) is the goal
  PlanLimits limits;
};

// The xi of eq. (6) at `distance` metres from the goal.
double HeuristicWeight(const HybridAStarOptions& options, double distance);

Result<MotionPath> PlanHybridAStar(const FootprintChecker& checker, const MotionPose& start,
                                   const MotionPose& goal, const HybridAStarOptions& options = {});

}  // namespace dispatch::engine
