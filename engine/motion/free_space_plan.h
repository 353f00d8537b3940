// Four-wheel-steer (4WIS) robots through the map's free-space regions (issue 17 §3, SPEC
// §3.7, BIT2024 step 6). Such a robot follows the road graph outside the regions and the
// hybrid A* (hybrid_astar.h) inside them: FreeSpaceMotion::Refine takes a plan built on the
// graph (BuildPlan) and replaces each stretch of it inside one region by hybrid A* paths
// between the stretch's anchors — the waypoint where it enters, every stop in it (a waypoint
// with an action other than move, or a dwell), the waypoint where it leaves — on that
// region's occupancy grid (free_space_grid.h). So the robot may crab into a slot, spin in
// place, and reach a stop with the heading its task asks for.
//
// Anchor headings: a stop's from `stop_headings` (keyed by its index in the input plan) when
// given; otherwise the direction of the graph arc the robot arrives by (a plan's first
// waypoint: the arc it leaves by). The stretch's last waypoint, when the plan goes on
// outside the region, faces down the arc it leaves by, so the robot leaves along its lane.
// A leg's waypoints: the path's poses every `keep_every` (metres driven, or radians spun)
// and wherever its mode changes, each a kMove waypoint with its heading and the mode that
// reaches it; the next anchor closes the leg at its own point and position with the anchor's
// heading. The waypoints are named after the graph route the leg replaces, in its order:
// each route point from the pose nearest to it on (not before the previous point's; a point
// no pose is nearest to gets a waypoint of its own at the same pose and time), so the traffic
// gate, which reasons on points and arcs, sees the robot pass the route's points one after
// another while it drives its own path. Times: translations and arcs at `speed`, spins at `spin_rate`; anchors
// keep their action and dwell, and every later waypoint moves by the change in duration.
// Sequence numbers run on from the plan's first. A stretch of one waypoint is left as it is
// (its heading set), and a plan that touches no region comes back unchanged.
// Errors: kInvalidArgument (bad options or speed, an anchor pose that does not fit the
// region: too near its border or a shelf), kUnreachable (no path between two anchors),
// kFailedPrecondition (the search limits stopped a search); the message names the region and
// the two points. Create builds every region's grid once; the object is immutable after it,
// safe to share between threads.
#pragma once

#include <cstddef>
#include <map>
#include <memory>
#include <vector>

#include "engine/common/result.h"
#include "engine/fleet/plan.h"
#include "engine/map/warehouse_map.h"
#include "engine/motion/footprint.h"
#include "engine/motion/hybrid_astar.h"
#include "engine/motion/occupancy_grid.h"

namespace dispatch::engine {

struct FreeSpaceMotionOptions {
  Footprint footprint;        // the robot's rectangle
  HybridAStarOptions search;  // its limits apply to each leg
  double resolution = 0.1;    // metres per grid cell
  double spin_rate = 1.0;     // radians per second, spinning in place
  double keep_every = 0.5;    // metres driven (or radians spun) between kept poses
};

class FreeSpaceMotion {
 public:
  static Result<FreeSpaceMotion> Create(std::shared_ptr<const WarehouseMap> map,
                                        FreeSpaceMotionOptions options = {});

  // Index of the free-space region holding graph point `point` (the first, if several do),
  // or npos.
  std::size_t RegionOf(PointId point) const;
  // See the file comment. `speed` in m/s (> 0).
  Result<Plan> Refine(const Plan& plan, double speed,
                      const std::map<std::size_t, double>& stop_headings = {}) const;

  const FreeSpaceMotionOptions& options() const { return options_; }

 private:
  struct Region {
    Region(OccupancyGrid g, const Footprint& footprint) : grid(std::move(g)), checker(grid, footprint) {}
    OccupancyGrid grid;
    FootprintChecker checker;  // refers to `grid`
  };
  FreeSpaceMotion() = default;

  std::shared_ptr<const WarehouseMap> map_;
  FreeSpaceMotionOptions options_;
  std::vector<std::unique_ptr<Region>> regions_;  // one per map free space (stable addresses)
  std::vector<std::size_t> region_of_point_;      // per point id
};

}  // namespace dispatch::engine
