// Poses, the motion modes of a four-wheel independent-steering (4WIS) robot and the path a
// motion planner returns (SPEC §3.7, BIT2024 step 6).
//
// A pose is (x, y) in metres on the floor and a heading theta in radians, counter-clockwise
// from +x, kept in (-pi, pi]. The modes are the seed's five kinds of motion (straight,
// reverse, crab, spin, steer), split by direction so that a path says exactly what the robot
// does: steer is one of four arcs of the minimum turning radius.
// Plain values; the functions are pure and thread-safe.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace dispatch::engine {

struct MotionPose {
  double x = 0.0;
  double y = 0.0;
  double theta = 0.0;
};

enum class MotionMode {
  kForward,          // straight ahead along the heading
  kReverse,          // straight back
  kCrabLeft,         // lateral, heading kept, towards heading + pi/2
  kCrabRight,        // lateral, towards heading - pi/2
  kSpinLeft,         // in place, counter-clockwise
  kSpinRight,        // in place, clockwise
  kArcForwardLeft,   // steer: forward on a left arc of the minimum turning radius
  kArcForwardRight,
  kArcReverseLeft,   // backwards with the wheels turned left (heading decreases)
  kArcReverseRight,
};

// "forward", "reverse", "crab_left", "crab_right", "spin_left", "spin_right",
// "arc_forward_left", "arc_forward_right", "arc_reverse_left", "arc_reverse_right".
const char* MotionModeName(MotionMode mode);
std::optional<MotionMode> ParseMotionMode(std::string_view name);

// What a change of mode costs the robot: a stop and a new wheel setting. Straight and arcs in
// the same direction of travel share a class (steering on the move needs no stop; the turn
// penalty of eq. (4) prices it); reverse, crab left, crab right and spin are classes of their
// own. A "mode switch" (BIT2024 eq. (4) lambda_switch, MotionPath::switches) is a change of class.
enum class DriveClass { kForward, kReverse, kCrabLeft, kCrabRight, kSpin };
DriveClass DriveClassOf(MotionMode mode);
bool IsArc(MotionMode mode);
bool IsSpin(MotionMode mode);

// Angle wrapped into (-pi, pi] (the same as fleet/formation.h WrapAngle, kept here so motion/
// does not depend on fleet/).
double WrapHeading(double angle);

// The pose reached from `from` after `amount` of `mode`: metres for translations and arcs
// (arc length, radius `radius`), radians for spins. `amount` >= 0. Exact (closed form).
MotionPose Advance(const MotionPose& from, MotionMode mode, double amount, double radius);

// A planned path. poses[i] -> poses[i + 1] is driven in modes[i]; consecutive poses are at
// most a planner sampling step apart, so checking every pose checks the swept path.
struct MotionPath {
  std::vector<MotionPose> poses;
  std::vector<MotionMode> modes;  // poses.size() - 1 entries (empty when poses has one)
  double length = 0.0;            // metres translated (spins add nothing)
  double rotation = 0.0;          // radians turned in place
  int switches = 0;               // changes of DriveClass along the path
  std::size_t nodes_expanded = 0; // search effort
  std::string finish;             // how the path reaches the goal: "search", "reeds_shepp", "crab"
};

// Fills length, rotation and switches of `path` from its poses and modes.
void Summarize(MotionPath& path);

}  // namespace dispatch::engine
