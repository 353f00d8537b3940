// CheckSafety: the reusable safety checker over sampled trajectories (STYLE.md "one reusable
// checker"; Chu2024 §3.3 eqs. (10)-(15); used by the simulator tests).
//
// Input: frames of sampled robot positions, each robot tagged with the agent that moves it
// (its own id, or a formation's id while the formation moves as one agent) and its groups
// (robots of one formation, including while they gather for the rendezvous and until they have
// split up after its drop, share a group and are exempt from each other). Reports:
//  - kSpacing: two robots of different groups closer than the pair's robot clearance
//    (TrafficConfig::RobotClearance: eps1 with defaults; eqs. (10)-(12));
//  - kCrossing: two agents inside one intersection's I_w (the bounding box of its inner
//    points, grown by `box_margin`) at the same time with different movements, a movement
//    being (nearest inner point when the agent's reference point entered the box, nearest
//    inner point when it left) (eqs. (13)-(15)); agents of one group are exempt. With
//    followers_may_diverge, so are two that entered an I_w of several points by the same inner
//    point, one behind the other in one lane (the spacing check still applies to them): the
//    online controller may turn the one ahead off, re-plan it, or back one off the way it came,
//    so their exits may differ without either crossing the other's path. Without it (the
//    default, the plan simulator's rule) every two movements that differ are reported.
// Also returns the minimum robot distance over all frames (pairs of different groups).
// Pure function; thread-safe.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "engine/map/warehouse_map.h"
#include "engine/traffic/traffic_config.h"

namespace dispatch::engine {

// The simulators check themselves with CheckSafety in debug builds (SimConfig::check_safety,
// StreamConfig::check_safety); release builds leave it to the caller.
#ifdef NDEBUG
inline constexpr bool kCheckSafetyByDefault = false;
#else
inline constexpr bool kCheckSafetyByDefault = true;
#endif

struct RobotSample {
  std::string robot;
  std::string agent;  // who moves it: robot id, or the formation's id
  std::string group;  // robots of one group never violate each other
  bool formation = false;
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();
  // A second and a third group, or "": a robot that has just left one formation's drop (or
  // two, in turn) while it already approaches the next formation's rendezvous is exempt from
  // the members of each.
  std::string group2 = {};
  std::string group3 = {};
};

struct SafetyFrame {
  double t = 0.0;
  std::vector<RobotSample> robots;  // robots on the floor at t
};

enum class ViolationKind { kSpacing, kCrossing };
const char* ViolationKindName(ViolationKind kind);

struct SafetyViolation {
  ViolationKind kind = ViolationKind::kSpacing;
  double t = 0.0;                  // first time seen (kCrossing: start of the overlap)
  std::string a, b;                // robots (kSpacing) or agents (kCrossing)
  double distance = 0.0;           // kSpacing: the closest distance of this episode
  double required = 0.0;           // kSpacing: the pair's clearance
  int intersection = -1;           // kCrossing
  std::string Describe() const;
};

struct SafetyCheckOptions {
  double tolerance = 1e-6;   // m: distances this much below the clearance still pass
  double box_margin = 0.05;  // m: I_w box growth (robots on its edge lanes count as inside)
  bool followers_may_diverge = false;  // see kCrossing above
};

struct SafetyReport {
  std::vector<SafetyViolation> violations;  // one per episode (consecutive frames) and pair
  double min_robot_distance = std::numeric_limits<double>::infinity();
  bool ok() const { return violations.empty(); }
};

SafetyReport CheckSafety(const std::vector<SafetyFrame>& frames, const WarehouseMap& map,
                         const TrafficConfig& config, const SafetyCheckOptions& options = {});

}  // namespace dispatch::engine
