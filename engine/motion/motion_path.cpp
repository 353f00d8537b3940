#include "engine/motion/motion_path.h"

#include <cmath>
#include <numbers>

namespace dispatch::engine {

const char* MotionModeName(MotionMode mode) {
  switch (mode) {
    case MotionMode::kForward: return "forward";
    case MotionMode::kReverse: return "reverse";
    case MotionMode::kCrabLeft: return "crab_left";
    case MotionMode::kCrabRight: return "crab_right";
    case MotionMode::kSpinLeft: return "spin_left";
    case MotionMode::kSpinRight: return "spin_right";
    case MotionMode::kArcForwardLeft: return "arc_forward_left";
    case MotionMode::kArcForwardRight: return "arc_forward_right";
    case MotionMode::kArcReverseLeft: return "arc_reverse_left";
    case MotionMode::kArcReverseRight: return "arc_reverse_right";
  }
  return "?";
}

std::optional<MotionMode> ParseMotionMode(std::string_view name) {
  for (int m = 0; m <= static_cast<int>(MotionMode::kArcReverseRight); ++m) {
    if (name == MotionModeName(static_cast<MotionMode>(m))) return static_cast<MotionMode>(m);
  }
  return std::nullopt;
}

DriveClass DriveClassOf(MotionMode mode) {
  switch (mode) {
    case MotionMode::kForward:
    case MotionMode::kArcForwardLeft:
    case MotionMode::kArcForwardRight: return DriveClass::kForward;
    case MotionMode::kReverse:
    case MotionMode::kArcReverseLeft:
    case MotionMode::kArcReverseRight: return DriveClass::kReverse;
    case MotionMode::kCrabLeft: return DriveClass::kCrabLeft;
    case MotionMode::kCrabRight: return DriveClass::kCrabRight;
    case MotionMode::kSpinLeft:
    case MotionMode::kSpinRight: return DriveClass::kSpin;
  }
  return DriveClass::kForward;
}

bool IsArc(MotionMode mode) {
  return mode == MotionMode::kArcForwardLeft || mode == MotionMode::kArcForwardRight ||
         mode == MotionMode::kArcReverseLeft || mode == MotionMode::kArcReverseRight;
}

bool IsSpin(MotionMode mode) { return mode == MotionMode::kSpinLeft || mode == MotionMode::kSpinRight; }

double WrapHeading(double angle) {
  constexpr double kPi = std::numbers::pi;
  double a = std::fmod(angle + kPi, 2.0 * kPi);
  if (a <= 0.0) a += 2.0 * kPi;
  return a - kPi;
}

MotionPose Advance(const MotionPose& from, MotionMode mode, double amount, double radius) {
  constexpr double kHalfPi = std::numbers::pi / 2.0;
  const double c = std::cos(from.theta);
  const double s = std::sin(from.theta);
  MotionPose to = from;
  // Arcs turn about a centre at `radius` to the left or right of the robot:
  // left centre (x - r sin, y + r cos), right centre (x + r sin, y - r cos).
  auto left_arc = [&](double dtheta) {
    to.theta = from.theta + dtheta;
    to.x = from.x + radius * (std::sin(to.theta) - s);
    to.y = from.y - radius * (std::cos(to.theta) - c);
  };
  auto right_arc = [&](double dtheta) {
    to.theta = from.theta + dtheta;
    to.x = from.x - radius * (std::sin(to.theta) - s);
    to.y = from.y + radius * (std::cos(to.theta) - c);
  };
  switch (mode) {
    case MotionMode::kForward: to.x += amount * c; to.y += amount * s; break;
    case MotionMode::kReverse: to.x -= amount * c; to.y -= amount * s; break;
    case MotionMode::kCrabLeft:
      to.x += amount * std::cos(from.theta + kHalfPi);
      to.y += amount * std::sin(from.theta + kHalfPi);
      break;
    case MotionMode::kCrabRight:
      to.x += amount * std::cos(from.theta - kHalfPi);
      to.y += amount * std::sin(from.theta - kHalfPi);
      break;
    case MotionMode::kSpinLeft: to.theta += amount; break;
    case MotionMode::kSpinRight: to.theta -= amount; break;
    case MotionMode::kArcForwardLeft: left_arc(amount / radius); break;
    case MotionMode::kArcReverseLeft: left_arc(-amount / radius); break;
    case MotionMode::kArcForwardRight: right_arc(-amount / radius); break;
    case MotionMode::kArcReverseRight: right_arc(amount / radius); break;
  }
  to.theta = WrapHeading(to.theta);
  return to;
}

void Summarize(MotionPath& path) {
  path.length = 0.0;
  path.rotation = 0.0;
  path.switches = 0;
  for (std::size_t i = 0; i < path.modes.size(); ++i) {
    const MotionPose& a = path.poses[i];
    const MotionPose& b = path.poses[i + 1];
    if (IsSpin(path.modes[i])) {
      path.rotation += std::abs(WrapHeading(b.theta - a.theta));
    } else {
      path.length += std::hypot(b.x - a.x, b.y - a.y);  // chords of arcs: sampled finely
    }
    if (i > 0 && DriveClassOf(path.modes[i]) != DriveClassOf(path.modes[i - 1])) ++path.switches;
  }
}

}  // namespace dispatch::engine
