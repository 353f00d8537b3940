#include "engine/motion/motion_path_check.h"

#include <cmath>
#include <string>

namespace dispatch::engine {
namespace {

constexpr double kTol = 1e-6;

// Why step a -> b cannot be driven in `mode`, or empty.
std::string StepProblem(const MotionPose& a, const MotionPose& b, MotionMode mode, const MotionPathCheck& check) {
  const double dx = b.x - a.x;
  const double dy = b.y - a.y;
  const double dtheta = WrapHeading(b.theta - a.theta);
  const double chord = std::hypot(dx, dy);
  const double along = std::cos(a.theta) * dx + std::sin(a.theta) * dy;
  const double across = -std::sin(a.theta) * dx + std::cos(a.theta) * dy;
  if (chord > check.max_gap + kTol) return "gap of " + std::to_string(chord) + " m";
  if (std::abs(dtheta) > check.max_turn + kTol) return "turn of " + std::to_string(dtheta) + " rad";
  switch (mode) {
    case MotionMode::kForward:
    case MotionMode::kReverse: {
      const bool ok = std::abs(dtheta) < kTol && std::abs(across) < kTol &&
                      (mode == MotionMode::kForward ? along > 0.0 : along < 0.0);
      return ok ? "" : "not a straight move";
    }
    case MotionMode::kCrabLeft:
    case MotionMode::kCrabRight: {
      const bool ok = std::abs(dtheta) < kTol && std::abs(along) < kTol &&
                      (mode == MotionMode::kCrabLeft ? across > 0.0 : across < 0.0);
      return ok ? "" : "not a crab move";
    }
    case MotionMode::kSpinLeft:
    case MotionMode::kSpinRight: {
      const bool ok = chord < kTol && (mode == MotionMode::kSpinLeft ? dtheta > 0.0 : dtheta < 0.0);
      return ok ? "" : "not a spin";
    }
    default: {
      // Arc: the chord of an arc of radius r turning by dtheta is 2 r sin(|dtheta| / 2); the
      // heading turns left on forward-left and reverse-right arcs, and the robot moves
      // forward (along > 0) on forward arcs.
      const bool left_turn = mode == MotionMode::kArcForwardLeft || mode == MotionMode::kArcReverseRight;
      const bool forward = mode == MotionMode::kArcForwardLeft || mode == MotionMode::kArcForwardRight;
      const bool ok = std::abs(chord - 2.0 * check.radius * std::sin(std::abs(dtheta) / 2.0)) < kTol &&
                      (left_turn ? dtheta > 0.0 : dtheta < 0.0) && (forward ? along > 0.0 : along < 0.0);
      return ok ? "" : "not an arc of radius " + std::to_string(check.radius);
    }
  }
}

}  // namespace

Status CheckMotionPath(const FootprintChecker& checker, const MotionPath& path, const MotionPose& start,
                       const MotionPose& goal, const MotionPathCheck& check) {
  if (path.poses.empty()) return InvalidArgument("path has no poses");
  if (path.modes.size() + 1 != path.poses.size()) return InvalidArgument("path needs one mode per step");
  const MotionPose& first = path.poses.front();
  if (std::hypot(first.x - start.x, first.y - start.y) > kTol || std::abs(WrapHeading(first.theta - start.theta)) > kTol) {
    return InvalidArgument("path does not start at the start pose");
  }
  const MotionPose& last = path.poses.back();
  if (std::hypot(last.x - goal.x, last.y - goal.y) > check.xy_tolerance ||
      std::abs(WrapHeading(last.theta - goal.theta)) > check.theta_tolerance) {
    return InvalidArgument("path ends at (" + std::to_string(last.x) + ", " + std::to_string(last.y) + ", " +
                           std::to_string(last.theta) + "), not at the goal");
  }
  for (std::size_t i = 0; i < path.poses.size(); ++i) {
    if (checker.Collides(path.poses[i])) return InvalidArgument("pose " + std::to_string(i) + " collides");
    if (i + 1 < path.poses.size()) {
      const std::string problem = StepProblem(path.poses[i], path.poses[i + 1], path.modes[i], check);
      if (!problem.empty()) {
        return InvalidArgument("step " + std::to_string(i) + " (" + MotionModeName(path.modes[i]) + "): " + problem);
      }
    }
  }
  return Ok{};
}

}  // namespace dispatch::engine
