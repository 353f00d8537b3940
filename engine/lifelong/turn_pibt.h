// PIBT for robots that turn (issue 19 §2: a rule-based planner for dense floors): Okumura et al.'s Priority Inheritance with Backtracking (AIJ 2022) decides each
// robot's next cell, and the MAPF_T model (grid_motion.h) turns the decision into an action.
//
// One step, for robots in priority order (a robot's priority grows by one every step it has a
// goal it has not reached and restarts, with a seeded fraction as tie-break, when its goal
// changes; a robot in a dead end (one free neighbour) gets kDeadEndBonus, as the LoRR start
// kit's planner does; robots without a goal come last):
//  1. PIBT: a robot takes the free candidate cell (its own and its free neighbours) with the
//     fewest steps to its goal through it: the route table's cost from the cell (routes.Cost:
//     the product's route oracle) plus the quarter turns to face it, plus kOccupiedCost when
//     another robot stands in it; for its own cell, its distance plus kStayCost; ties to the nearer cell, then fewer turns, then seeded random. The cell it turns
//     towards comes first while it turns (below). A robot standing in the chosen cell
//     is pushed (priority inheritance) and must leave it, never into the pusher's cell; a
//     pushed robot that cannot leave makes its pusher try its next candidate. A swap that pushes
//     cannot make (the best cell is a dead end whose robot must come out through this robot's
//     cell; Okumura's swap situation, its dead-end case) makes the robot back away instead and
//     that robot follow into the cell it leaves.
//  2. Actions: the robot's own cell -> W; the cell it faces -> F; another cell -> the turn
//     towards it (clockwise when behind), and the robot keeps that cell as its target while it
//     turns (it tries it first next step), so turning is not undone.
//  3. Causal check: a forward move stands only if the robot in the cell ahead leaves it
//     forwards too (a chain of followers, or a closed cycle); else the robot waits, and so does
//     every robot behind it. The joint step is then legal by construction (no vertex conflict,
//     no swap).
// Not complete: swaps in corridors longer than one cell can still hold robots up until their
// priorities change. O(robots) per step (no deadline needed). Deterministic for a seed. Not
// thread-safe; one planner per run.
#pragma once

#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include "engine/lifelong/grid_motion.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine {

class TurnPibt {
 public:
  // `routes` answers costs between `grid`'s map points (one step per cell).
  TurnPibt(const LorrGrid& grid, std::shared_ptr<const RouteTable> routes, std::uint64_t seed = 0);

  // Actions for robots at `poses` with goals `goals` (a cell, or -1 for none); sizes equal and
  // constant over a run.
  std::vector<GridAction> Step(const std::vector<GridPose>& poses, const std::vector<int>& goals);

 private:
  bool Push(int robot, int banned_cell);
  double Distance(int cell, int goal) const;
  // kDeadEndBonus for a cell with one free neighbour (a robot there can only leave one way,
  // so it goes first), else 0.
  double DeadEndBonus(int cell) const;
  static constexpr double kDeadEndBonus = 10.0;
  // What staying costs a robot with a goal, in steps, when candidates are ranked (measured on
  // random_32_32_20_100: 1.5 and 2 rank alike; 1 lets robots facing away wait instead of turn).
  static constexpr double kStayCost = 1.5;
  // What a neighbour another robot stands in costs beyond its steps: a free cell goes first
  // among equals, and a robot does not push another to move away from its own goal (that
  // ties with staying, and the tie goes to the nearer cell). Measured on random_32_32_20_100,
  // seeds 0-7: mean 845.6 tasks without, 851.6 with 0.1-0.4, 857.4 with 0.5; from 0.75 robots
  // facing away from an occupied cell wait instead of pushing, and runs lock up (314-759).
  static constexpr double kOccupiedCost = 0.5;

  const LorrGrid& grid_;
  std::shared_ptr<const RouteTable> routes_;
  std::mt19937_64 random_;
  std::vector<double> priority_;
  std::vector<int> last_goal_;
  std::vector<int> target_;  // the cell a robot turns towards, or -1
  // One step's working state.
  const std::vector<GridPose>* poses_ = nullptr;
  const std::vector<int>* goals_ = nullptr;
  std::vector<int> next_;           // per robot: the chosen cell, -1 undecided
  std::vector<int> occupant_;       // per cell: the robot standing there, -1
  std::vector<int> reserved_;       // per cell: the robot that chose it, -1
  std::vector<int> touched_cells_;  // cells whose occupant_/reserved_ to reset
};

}  // namespace dispatch::engine
