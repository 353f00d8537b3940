// The one checker of a MotionPath, for tests and debug builds (STYLE.md, lacam3's
// is_feasible_solution): the path starts at `start`, ends within tolerance of `goal`, every
// pose is collision-free, consecutive poses are at most `max_gap` metres (translation) and
// `max_turn` radians (spin) apart, and each step moves the way its mode says (straight moves
// keep the heading and go along it, crabs keep it and go across it, spins stay in place,
// arcs keep the chord of radius `radius` and turn the right way).
// Pure; thread-safe.
#pragma once

#include "engine/common/result.h"
#include "engine/motion/footprint.h"
#include "engine/motion/motion_path.h"

namespace dispatch::engine {

struct MotionPathCheck {
  double radius = 0.8;          // minimum turning radius of the arcs
  double max_gap = 0.06;        // metres between consecutive poses
  double max_turn = 0.2;        // radians between consecutive poses
  double xy_tolerance = 0.1;    // metres, end vs goal
  double theta_tolerance = 0.0873;
};

Status CheckMotionPath(const FootprintChecker& checker, const MotionPath& path, const MotionPose& start,
                       const MotionPose& goal, const MotionPathCheck& check = {});

}  // namespace dispatch::engine
