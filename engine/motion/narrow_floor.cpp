#include "engine/motion/narrow_floor.h"

#include <algorithm>
#include <numbers>
#include <random>
#include <string>

namespace dispatch::engine {

NarrowFloor BuildNarrowFloor() {
  constexpr double kPi = std::numbers::pi;
  OccupancyGrid grid(120, 60, 0.1);
  auto rect = [&grid](double x0, double y0, double x1, double y1, bool occupied) {
    grid.SetRect({x0, y0}, {x1, y1}, occupied);
  };
  rect(0.0, 0.0, 12.0, 6.0, true);     // solid; free space is carved out below
  rect(0.1, 0.1, 11.9, 1.5, false);    // corridor, 1.4 m wide
  rect(3.0, 1.5, 4.0, 2.15, false);    // crab slot: 1.0 m long, 0.65 m deep
  rect(5.0, 1.5, 7.0, 2.6, false);     // opening from the corridor to the hall
  rect(0.1, 2.6, 7.5, 5.9, false);     // hall
  rect(1.0, 3.7, 3.0, 4.3, true);      // shelf S1
  rect(4.0, 3.7, 6.0, 4.3, true);      // shelf S2
  rect(8.5, 1.5, 9.6, 5.9, false);     // dead-end aisle, 1.1 m wide, closed at the top
  grid.ComputeClearance();
  return NarrowFloor{
      .grid = std::move(grid),
      .footprint = {0.8, 0.5, 0.0},
      .min_turn_radius = 0.8,
      .crab_start = {1.0, 0.8, 0.0},
      .crab_goal = {3.5, 1.825, 0.0},
      .dead_end_start = {9.05, 5.3, kPi / 2.0},
      .dead_end_goal = {10.8, 0.8, 0.0},
      .cross_start = {0.8, 0.8, 0.0},
      .cross_goal = {2.0, 5.1, kPi},
      .stations = {{0.7, 3.15, 0.0}, {3.5, 3.15, 0.0}, {7.0, 3.15, kPi / 2}, {0.7, 5.1, 0.0},
                   {3.5, 5.1, 0.0},  {6.8, 5.1, kPi},  {5.2, 5.5, 0.0},      {1.0, 0.8, 0.0},
                   {10.8, 0.8, kPi}, {3.5, 1.825, 0.0}, {6.0, 2.0, kPi / 2}, {9.05, 5.3, kPi / 2}},
  };
}

Result<std::vector<MotionRobot>> NarrowFloorRobots(const NarrowFloor& floor, std::size_t robots, std::uint64_t seed) {
  const std::vector<MotionPose>& stations = floor.stations;
  if (robots * 2 > stations.size()) {
    return InvalidArgument("at most " + std::to_string(stations.size() / 2) + " robots fit the floor's " +
                           std::to_string(stations.size()) + " stations");
  }
  std::vector<std::size_t> order(stations.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::mt19937_64 random(seed);
  std::shuffle(order.begin(), order.end(), random);
  std::vector<MotionRobot> out;
  for (std::size_t i = 0; i < robots; ++i) {
    out.push_back({stations[order[i]], stations[order[robots + i]], floor.footprint});
  }
  return out;
}

}  // namespace dispatch::engine
