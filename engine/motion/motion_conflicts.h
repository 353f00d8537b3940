// Timed 4WIS paths and the conflicts between them (SPEC §3.7, BIT2024 step 7 s72: "whether
// two or more robots are at the same place of the map at the same moment", seed 003 lines
// 96-103 and claim 7). Continuous-pose counterpart of engine/planning/timed_paths.h.
//
// Timing model: a MotionPath's poses are sampled finely (motion_path.h); the robot drives each
// step at a constant rate — translations (straight, reverse, crab, arcs: the chord, which the
// fine sampling makes the arc) at `speed` m/s, spins at `spin_rate` rad/s — with no
// acceleration and no stop at a mode switch. The robot stands at its start pose from time 0
// until `start_time` (a delay is waiting there) and at its goal pose from its arrival on.
// PoseAt interpolates linearly between samples (heading the short way round).
//
// "Same place at the same moment": time is sampled at k * time_step (k = 0, 1, ...) up to the
// last arrival; at each sample the two robots' footprint rectangles (footprint.h), each grown
// by `clearance / 2` on every side on top of its own margin, overlap (separating-axis test;
// touching is no overlap). Between samples nothing is checked: at 0.1 s and 0.5 m/s a robot
// moves 5 cm, well under a robot's size, so no robot passes through another unseen, but two
// footprints may come up to (closing speed * time_step) closer than `clearance` for an
// instant; choose clearance with that in mind.
// Pure values and functions; thread-safe.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "engine/common/result.h"
#include "engine/motion/footprint.h"
#include "engine/motion/motion_path.h"
#include "engine/motion/occupancy_grid.h"

namespace dispatch::engine {

struct MotionTiming {
  double speed = 0.5;      // m/s for straight, reverse, crab and arc moves
  double spin_rate = 1.0;  // rad/s in place
};

// A path with a time (seconds) for every pose: times[0] = start_time, non-decreasing.
struct TimedMotionPath {
  MotionPath path;
  std::vector<double> times;
  double start_time = 0.0;
  double arrival() const { return times.empty() ? start_time : times.back(); }
};

// Times `path` (at least one pose) from `start_time` >= 0 under `timing` (speed, spin_rate > 0).
TimedMotionPath TimeMotionPath(MotionPath path, double start_time, const MotionTiming& timing);

// Where the robot is at time `t`: its start pose before start_time, its goal pose after arrival.
MotionPose PoseAt(const TimedMotionPath& timed, double t);

// The four corners of `footprint` at `pose`, grown by `grow` (on top of footprint.margin) on
// every side, counter-clockwise.
std::vector<std::pair<double, double>> FootprintCorners(const MotionPose& pose, const Footprint& footprint,
                                                        double grow);

// True when the two rectangles overlap (separating-axis theorem; touching is no overlap).
bool FootprintsOverlap(const MotionPose& a, const Footprint& fa, const MotionPose& b, const Footprint& fb,
                       double grow);

// Cells of `grid` (in or out of bounds, as (ix, iy)) whose interior the footprint at `pose`,
// grown by `grow`, overlaps.
std::vector<std::pair<int, int>> FootprintCells(const OccupancyGrid& grid, const MotionPose& pose,
                                                const Footprint& footprint, double grow);

struct MotionConflictOptions {
  double time_step = 0.1;   // seconds between the compared samples
  double clearance = 0.1;   // metres required between two footprints
};

struct MotionConflict {
  int a = -1;  // robot indices, a < b
  int b = -1;
  double time = 0.0;  // the first sampled moment they overlap
  MotionPose pose_a;
  MotionPose pose_b;
};
std::string Describe(const MotionConflict& conflict);

// The earliest sampled conflict between any two of `paths` (robot i has footprints[i]); ties
// in time go to the lowest (a, b). nullopt: conflict-free. paths.size() == footprints.size().
std::optional<MotionConflict> FirstMotionConflict(const std::vector<TimedMotionPath>& paths,
                                                  const std::vector<Footprint>& footprints,
                                                  const MotionConflictOptions& options = {});

// The one checker for tests and debug builds: every timed path is well formed (a time per
// pose, non-decreasing, starting at start_time) and no two conflict.
Status CheckTimedMotionPaths(const std::vector<TimedMotionPath>& paths, const std::vector<Footprint>& footprints,
                             const MotionConflictOptions& options = {});

}  // namespace dispatch::engine
