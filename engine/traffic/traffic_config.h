// Traffic-rule settings of the local traffic layer (Chu2024 §3.3, eqs. (10)-(15); SPEC §3.5).
//
// Safety distances are measured between AGENT reference points: a single robot's centre, or
// a formation's virtual-structure centre (Chu2024 eq. (9)); a formation is one agent.
//  - eps1 (eqs. (10), (13)) single-single: 0.6 m = robot diameter 0.4 m + 0.2 m gap, the
//    paper's Fig. 8 bound ("always > 0.6 m with rules").
//  - eps2 (eqs. (11), (14)) single-formation: eps1 + D_f, where D_f = 0.4/sqrt(3) ~ 0.231 m is
//    the formation's circumradius: the formation envelope (D_f + robot radius 0.2 m) keeps
//    the same 0.2 m body gap to a single robot (0.2 + 0.2 + 0.431 ~ 0.831 m).
//  - eps3 (eqs. (12), (15)) formation-formation: eps1 + 2 D_f ~ 1.062 m (two envelopes).
// Since every member lies within D_f of its centre, keeping these agent distances keeps every
// pair of robots of different agents at least RobotClearance() apart (eps1 with defaults).
//
// Invariants (Validate): all distances finite, eps > 0, formation_radius >= 0 and
// RobotClearance(...) > 0 for every pair kind. Plain value; thread-safe to share.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>

#include "engine/common/result.h"

namespace dispatch::engine {

struct TrafficConfig {
  double robot_diameter = 0.4;                           // m
  double formation_radius = 0.4 / std::sqrt(3.0);        // D_f of eq. (9), m
  double epsilon_single_single = 0.6;                    // eps1, m
  double epsilon_single_formation = 0.6 + 0.4 / std::sqrt(3.0);          // eps2, m
  double epsilon_formation_formation = 0.6 + 2.0 * 0.4 / std::sqrt(3.0);  // eps3, m
  // Rules on: intersection grants (eqs. (13)-(15)) and the rear-end rule (eqs. (10)-(12)).
  // Rules off: robots just follow their timed paths (the paper's "without rules" run).
  bool rules_enabled = true;
  // Also guard merge points outside intersections (points with >= 2 incoming arcs: station
  // spurs and pick docks joining a lane) with grants, like a one-point intersection.
  bool guard_merges = true;
  // Members of one formation within this distance of its rendezvous centre are exempt from
  // each other (their slots are a triangle side, 0.4 m, apart); farther out they keep eps1.
  double gather_radius = 0.6 + 2.0 * 0.4 / std::sqrt(3.0);

  // The pair's safety distance between agent reference points: eps1, eps2 or eps3.
  double Epsilon(bool a_formation, bool b_formation) const {
    if (a_formation && b_formation) return epsilon_formation_formation;
    if (a_formation || b_formation) return epsilon_single_formation;
    return epsilon_single_single;
  }
  // Distance an agent keeps from a crossing point that another agent may pass through: the
  // largest eps it has with any kind of agent. Its stop line before an intersection (and its
  // release point after one) lies this far from the first (last) inner point.
  double Clearance(bool formation) const {
    return formation ? std::max(epsilon_single_formation, epsilon_formation_formation)
                     : std::max(epsilon_single_single, epsilon_single_formation);
  }
  // Minimum robot-centre distance implied for robots of two different agents.
  double RobotClearance(bool a_formation, bool b_formation) const {
    return Epsilon(a_formation, b_formation) - (a_formation ? formation_radius : 0.0) -
           (b_formation ? formation_radius : 0.0);
  }

  Status Validate() const {
    for (double v : {robot_diameter, formation_radius, epsilon_single_single,
                     epsilon_single_formation, epsilon_formation_formation}) {
      if (!std::isfinite(v) || v < 0) return InvalidArgument("traffic config: bad distance");
    }
    if (epsilon_single_single <= 0 || RobotClearance(true, false) <= 0 ||
        RobotClearance(true, true) <= 0) {
      return InvalidArgument("traffic config: eps must exceed the formation envelope");
    }
    return Ok{};
  }
};

}  // namespace dispatch::engine
