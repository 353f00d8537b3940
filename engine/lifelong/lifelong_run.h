// The LoRR 2024 lifelong run (issue 19 §2): robots on a LorrProblem's grid finish as many tasks
// as they can in a number of one-second steps, dispatched by the product's components.
//
// Each step t (the competition's order, v2.1.2):
//  1. Schedule: the revealed tasks no robot holds go to the robots without a task through the
//     product's allocation strategy (MakeAllocator: exact by default, auction, greedy, psoga), as
//     orders (picks = all errands but the last, drop = the last, no work time) on the grid's map
//     with a FleetState of the free robots, one task each at most (max_queue = 1: for `exact`
//     the round is one assignment problem, the cheapest tasks to serve go to the free robots).
//     A robot keeps its task until it is finished (the competition forbids taking an opened
//     task away).
//  2. Plan: TurnPibt gives every robot an action towards its task's next errand.
//  3. Move: the joint step is checked (CheckJointStep); an illegal one is logged as a planner
//     error and every robot waits instead.
//  4. Errands (at t + 1): a robot standing on its task's next errand has done it (at most one
//     per step; an event [t + 1, robot, task, errands done]); a task with every errand done is
//     finished and its robot is free.
//  5. Reveal: tasks are revealed in file order (wrapping round the file; a task's id counts on)
//     until numTasksReveal x teamSize unfinished ones are out.
// When a step's scheduling and planning take longer than `plan_ms` (0: no limit), the
// competition's robots would have waited: the run counts an entry timeout and every robot waits
// ('T') for each whole `plan_ms` over, before the late actions are applied. Deterministic for a
// seed when plan_ms = 0, except where a strategy's own time budget runs out (the exact
// strategy's chunks on a round too large for one assignment: the first step of the large
// floors).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "engine/common/result.h"
#include "engine/lifelong/grid_motion.h"
#include "engine/lifelong/lorr_problem.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine {

struct LifelongOptions {
  int steps = 100;
  double plan_ms = 0.0;           // the per-step time limit, ms; 0 = none
  std::string strategy = "exact";  // MakeAllocator's names
  std::uint64_t seed = 0;
  // The route table's cache on floors above RouteTableOptions::lazy_threshold_points (the
  // lazy table: 12 bytes per cell per destination; every robot's goal and every waiting
  // task's pickup is a destination, so the LoRR warehouse floors need a few GiB).
  std::size_t route_cache_bytes = std::size_t{4} << 30;
  // Polled between steps: true stops the run early (its record holds the steps done).
  std::function<bool()> cancelled;
  // kFloyd: the dense table below RouteTableOptions::lazy_threshold_points, the lazy one above;
  // kHubLabels: hub labels on any floor (memory bounded by the labels, no search per goal).
  RouteTableMethod route_method = RouteTableMethod::kFloyd;
  // Tasks whose first errand no robot has reached yet go back into the pool with the waiting
  // ones, and their robots bid again with the free ones (the competition lets a scheduler move
  // a task until it is opened). A robot that wins nothing keeps its task unless another robot
  // won it. The work of such a pool is min(robots, tasks)^2 x max(robots, tasks) (what the
  // assignment costs; its cost matrix is robots x tasks route queries). A step reassigns when
  // its pool's work is at most reassign_max_work and within the credit: every step adds
  // reassign_work_per_step to it (kept at most reassign_max_work), a reassignment spends its
  // work. So pools within reassign_work_per_step (the LoRR random floor's: 100 robots, 150
  // tasks, at most 1.5e6) reassign every step, and larger ones every few steps, about their
  // work / reassign_work_per_step: on sortation_large_2000 (pools of about 170 robots and
  // 1,170 tasks, 3.5e7) about one step in four, as many tasks as reassigning every step at
  // about half its time (60-63 ms a step instead of 113-124: README). Deterministic: the rule
  // counts work, not time. Other steps give the waiting tasks to the free robots only.
  bool reassign = true;
  double reassign_max_work = 1e8;
  double reassign_work_per_step = 1e7;
};

struct LifelongError {
  int robot = 0;
  int other = -1;
  int step = 0;
  std::string what;
};

struct LifelongEvent {
  int step = 0;
  int robot = 0;
  int task = 0;
  int errands_done = 0;
};

struct RevealedTask {
  int id = 0;
  int release_step = 0;
  std::vector<int> errands;
};

// What a run did, in the competition output's terms (lorr_output.h writes it).
struct LifelongRecord {
  std::string strategy;
  int team_size = 0;
  int steps = 0;  // steps simulated, timeout steps included
  int tasks_finished = 0;
  int makespan = 0;  // the most steps any robot had a task
  int planner_errors = 0;
  int schedule_errors = 0;
  int entry_timeouts = 0;
  std::vector<GridPose> starts;
  std::vector<std::string> actual_actions;   // per robot, one letter per step: F R C W T
  std::vector<std::string> planner_actions;  // the actions as planned
  std::vector<double> planner_seconds;       // per step planned
  std::vector<LifelongError> errors;
  std::vector<std::vector<std::pair<int, int>>> actual_schedule;   // per robot: (step, task or -1) on change
  std::vector<std::vector<std::pair<int, int>>> planner_schedule;  // the same, as proposed
  std::vector<LifelongEvent> events;
  std::vector<RevealedTask> tasks;
  std::string routes;  // the route table that ran (RouteTable::method())
  int reassign_steps = 0;  // steps whose pool took back the tasks not opened yet (reassign)
};

Result<LifelongRecord> RunLifelong(const LorrProblem& problem, const LifelongOptions& options);

}  // namespace dispatch::engine
