// The built-in narrow-area scenario floor for the 4WIS hybrid A* (SPEC §3.7, BIT2024 step 6):
// a 12 m x 6 m occupancy grid of 0.1 m cells built in code, with a crab parking slot, a
// dead-end aisle narrower than a turning circle and a cross-floor query with a heading goal.
// Layout, dimensions and why each feature tests what it does: narrow_floor.md.
// Pure; the returned value is independent of every other.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "engine/common/result.h"
#include "engine/motion/footprint.h"
#include "engine/motion/motion_conflict_elimination.h"
#include "engine/motion/motion_path.h"
#include "engine/motion/occupancy_grid.h"

namespace dispatch::engine {

struct NarrowFloor {
  OccupancyGrid grid;            // clearance computed
  Footprint footprint;           // the scenario's robot: 0.8 m x 0.5 m
  double min_turn_radius = 0.8;  // metres
  // Parking: from the corridor into the side slot, same heading (only crabbing fits).
  MotionPose crab_start;
  MotionPose crab_goal;
  // Leaving the dead-end aisle: starts facing its end wall.
  MotionPose dead_end_start;
  MotionPose dead_end_goal;
  // Across the floor: corridor -> the hall's upper lane, facing west.
  MotionPose cross_start;
  MotionPose cross_goal;
  // Where several robots start and end (BIT2024 step 7): hall, corridor ends, crab slot,
  // opening, dead end; every one free.
  std::vector<MotionPose> stations;
};

NarrowFloor BuildNarrowFloor();

// `robots` robots, starts and goals drawn without repeats among the floor's stations (seeded).
// kInvalidArgument for more robots than half the stations.
Result<std::vector<MotionRobot>> NarrowFloorRobots(const NarrowFloor& floor, std::size_t robots, std::uint64_t seed);

}  // namespace dispatch::engine
