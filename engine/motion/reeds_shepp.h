// Reeds-Shepp paths (Reeds & Shepp 1990, "Optimal paths for a car that goes both forwards and
// backwards"): shortest paths of a car of minimum turning radius r that may reverse, built
// from arcs of radius r (L, R) and straight segments (S). Used by the hybrid A*'s analytic
// expansion near the goal (BIT2024 step 6).
//
// Families implemented (formula numbers of the paper's §8, as the common formulation and OMPL
// number them), each with the time-flip and reflection symmetries and, where marked, the
// backwards (reversed-order) form — 44 candidate words per query:
//   CSC          (8.1, 8.2):   L+S+L+, L+S+R+                                   8 words
//   C|C|C        (8.3):        L+R-L+, with backwards                           8 words
//   CC|CC        (8.7, 8.8):   L+R+L-R-, L+R-L-R+                               8 words
//   C|CSC, CSC|C (8.9, 8.10):  L+R-(pi/2)S-L-, L+R-(pi/2)S-R-, with backwards  16 words
//   C|CSC|C      (8.11):       L+R-(pi/2)S-L-(pi/2)R+                           4 words
// Reeds & Shepp's table has 48 words; the C|CC and CC|C forms are not generated on their own
// here, so for some goals the returned "shortest" may be longer than the true optimum. It is
// never wrong: every candidate is integrated and kept only when it ends at the goal (1e-6).
// Pure functions; thread-safe.
#pragma once

#include <vector>

#include "engine/motion/motion_path.h"

namespace dispatch::engine {

struct RsSegment {
  char type = 'S';      // 'L', 'S' or 'R'
  double length = 0.0;  // metres (arc length for L and R); negative = driven backwards
};

struct RsPath {
  std::vector<RsSegment> segments;
  double length = 0.0;  // sum of |segment lengths|, metres
};

// Every Reeds-Shepp path of the families above from `start` to `goal` for turning radius
// `radius` > 0, sorted by length (ties keep family order, so the result is deterministic).
// Empty segments (|length| < 1e-9) are dropped.
std::vector<RsPath> ReedsSheppPaths(const MotionPose& start, const MotionPose& goal, double radius);

// The shortest of them; an empty path when there is none (start == goal; never seen
// otherwise: the random-query test finds a path for every one of its 500 queries).
RsPath ShortestReedsShepp(const MotionPose& start, const MotionPose& goal, double radius);

// The motion mode of a segment: S+ forward, S- reverse, L+ arc_forward_left, L- arc_reverse_left, ...
MotionMode RsSegmentMode(const RsSegment& segment);

// Poses along `path` from `start`, at most `spacing` metres apart, both ends included, and
// modes[i] for poses[i] -> poses[i + 1]. Appends to `out` (its first pose, if any, must be
// `start`; it is not repeated).
void SampleReedsShepp(const MotionPose& start, const RsPath& path, double radius, double spacing,
                      MotionPath& out);

}  // namespace dispatch::engine
