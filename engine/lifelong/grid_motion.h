// The competition's motion model, "MAPF_T" (LoRR 2024; issue 19 §2): every robot stands on a
// cell facing one of four directions; each one-second step it moves one cell forward (F), turns
// 90° clockwise (R) or counter-clockwise (C), or waits (W). A joint step is legal when no robot
// drives into a blocked cell or off the grid, no two robots end in one cell, and no two robots
// swap cells. Following is legal: a robot may drive into the cell another one leaves in the
// same step (and a closed cycle of forward moves is too: it is neither a vertex nor a swap).
//
// Directions are the competition's: 0 east (column + 1), 1 south (row + 1), 2 west, 3 north;
// clockwise turns east -> south. Pure functions; thread-safe.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "engine/lifelong/lorr_problem.h"

namespace dispatch::engine {

enum class GridAction : char { kForward = 'F', kClockwise = 'R', kCounterClockwise = 'C', kWait = 'W' };

struct GridPose {
  int cell = 0;
  int direction = 0;  // 0 east, 1 south, 2 west, 3 north
  friend bool operator==(const GridPose&, const GridPose&) = default;
};

// "E", "S", "W", "N".
const char* DirectionName(int direction);
// The cell one step from `cell` towards `direction`, or -1 off the grid (blocked cells count).
int CellTowards(const LorrGrid& grid, int cell, int direction);
// The pose after `action` (a forward move off the grid or into a blocked cell stays: the
// caller checks legality with CheckJointStep).
GridPose Apply(const LorrGrid& grid, const GridPose& pose, GridAction action);
// Quarter turns to face `direction` from `from` (0, 1 or 2).
int TurnsBetween(int from, int direction);
// The turn towards `direction` (clockwise when it is behind), kWait when already facing it.
GridAction TurnTowards(int from, int direction);

struct StepViolation {
  int robot = 0;   // the robot that broke the rule (the later one of a pair)
  int other = -1;  // the other robot of a vertex or swap conflict
  std::string what;  // "robot 3 drives into blocked cell 41", "robots 1 and 2 swap cells 7 and 8"
};

// Every rule a joint step breaks (empty: legal). `actions` has one entry per pose.
std::vector<StepViolation> CheckJointStep(const LorrGrid& grid, const std::vector<GridPose>& poses,
                                          const std::vector<GridAction>& actions);

}  // namespace dispatch::engine
