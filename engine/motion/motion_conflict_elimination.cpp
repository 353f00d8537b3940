#include "engine/motion/motion_conflict_elimination.h"

#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <utility>

namespace dispatch::engine {
namespace {

struct RobotState {
  MotionPath path;
  std::vector<std::uint8_t> detour;  // per in-bounds cell: forbidden by a detour constraint
  std::vector<std::uint8_t> own;     // per in-bounds cell: under the robot's start or goal
  double delay = 0.0;
  int failed_detours = 0;
};

bool Stopped(const PlanLimits& limits) { return limits.stop && limits.stop(); }

}  // namespace

Result<MotionFleetSolution> EliminateMotionConflicts(const OccupancyGrid& grid, const std::vector<MotionRobot>& robots,
                                                     const MotionConflictEliminationOptions& options) {
  if (robots.empty()) return InvalidArgument("motion conflicts: no robots");
  if (!(options.timing.speed > 0.0) || !(options.timing.spin_rate > 0.0) || !(options.conflicts.time_step > 0.0) ||
      options.conflicts.clearance < 0.0 || !(options.delay_step > 0.0) || options.max_delay < 0.0 ||
      options.constraint_window < 0.0) {
    return InvalidArgument("motion conflicts: options out of range");
  }
  const std::size_t n = robots.size();
  const std::size_t cells = static_cast<std::size_t>(grid.width()) * grid.height();
  std::vector<Footprint> footprints;
  for (const MotionRobot& r : robots) footprints.push_back(r.footprint);
  HybridAStarOptions planner = options.planner;
  planner.limits = PlanLimits{options.limits.stop, options.replan_expansions};

  MotionFleetSolution out;
  std::vector<RobotState> state(n);
  auto fail = [](std::size_t i, const Error& e) {
    return Error{e.code, "motion conflicts: robot " + std::to_string(i) + ": " + e.message};
  };
  // s71: each robot alone.
  for (std::size_t i = 0; i < n; ++i) {
    const FootprintChecker checker(grid, robots[i].footprint);
    auto found = PlanHybridAStar(checker, robots[i].start, robots[i].goal, planner);
    ++out.searches;
    if (!found.ok()) return fail(i, found.error());
    state[i].path = std::move(found.value());
    state[i].detour.assign(cells, 0);
    state[i].own.assign(cells, 0);
    for (const MotionPose& p : {robots[i].start, robots[i].goal}) {
      for (const auto& [ix, iy] : FootprintCells(grid, p, robots[i].footprint, 1e-3)) {
        if (grid.InBounds(ix, iy)) state[i].own[static_cast<std::size_t>(iy) * grid.width() + ix] = 1;
      }
    }
  }
  auto timed = [&] {
    std::vector<TimedMotionPath> paths;
    for (const RobotState& s : state) paths.push_back(TimeMotionPath(s.path, s.delay, options.timing));
    return paths;
  };
  std::vector<TimedMotionPath> paths = timed();

  std::mt19937_64 random(options.seed);
  std::map<std::size_t, int> kept;  // pair a * n + b -> the robot that keeps its path
  while (true) {
    // s72: the first conflict, or done.
    const auto c = FirstMotionConflict(paths, footprints, options.conflicts);
    if (!c) break;
    ++out.rounds;
    if (options.limits.Exhausted(out.rounds)) {
      return Error{ErrorCode::kFailedPrecondition,
                   "motion conflicts: stopped after " + std::to_string(out.rounds) + " rounds at " + Describe(*c)};
    }
    // The kept robot: drawn at random the first time a pair meets, the same one afterwards
    // (drawing again each round would let two robots take turns waiting, forever).
    auto [drawn, fresh] = kept.try_emplace(static_cast<std::size_t>(c->a) * n + static_cast<std::size_t>(c->b), -1);
    if (fresh) drawn->second = random() % 2 == 0 ? c->a : c->b;
    int keep = drawn->second;
    std::size_t o = static_cast<std::size_t>(keep == c->a ? c->b : c->a);
    // Waiting longer gives way to nobody when the robot to wait is still waiting at its start,
    // or the kept one is parked at its goal: then the kept one is constrained this round (it
    // detours round, or arrives after, the standing robot), unless it is itself still waiting.
    const TimedMotionPath& to_wait = paths[o];
    const TimedMotionPath& to_keep = paths[static_cast<std::size_t>(keep)];
    if ((c->time <= to_wait.start_time || c->time >= to_keep.arrival()) && c->time > to_keep.start_time) {
      const int waiting = static_cast<int>(o);
      o = static_cast<std::size_t>(keep);
      keep = waiting;
      drawn->second = keep;  // and from now on for this pair, or the two take turns waiting
    }
    RobotState& s = state[o];
    // s73, the detour: the kept robot's cells around the conflict, as static obstacles.
    bool detoured = false;
    if (s.failed_detours < options.max_detours) {
      std::vector<std::uint8_t> detour = s.detour;
      int added = 0;
      const TimedMotionPath& keeper = paths[static_cast<std::size_t>(keep)];
      const double step = options.conflicts.time_step;
      const int half = static_cast<int>(std::ceil(options.constraint_window / step - 1e-9));
      for (int k = -half; k <= half; ++k) {
        const double t = c->time + k * step;
        if (t < 0.0) continue;
        for (const auto& [ix, iy] : FootprintCells(grid, PoseAt(keeper, t), robots[static_cast<std::size_t>(keep)].footprint,
                                                   options.conflicts.clearance)) {
          if (!grid.InBounds(ix, iy)) continue;
          const std::size_t cell = static_cast<std::size_t>(iy) * grid.width() + ix;
          if (s.own[cell] || detour[cell] || grid.Occupied(ix, iy)) continue;
          detour[cell] = 1;
          ++added;
        }
      }
      if (added > 0) {
        OccupancyGrid constrained = grid;
        for (std::size_t cell = 0; cell < cells; ++cell) {
          if (detour[cell]) constrained.Set(static_cast<int>(cell % grid.width()), static_cast<int>(cell / grid.width()), true);
        }
        constrained.ComputeClearance();
        const FootprintChecker checker(constrained, robots[o].footprint);
        auto found = PlanHybridAStar(checker, robots[o].start, robots[o].goal, planner);
        ++out.searches;
        if (found.ok()) {
          s.path = std::move(found.value());
          s.detour = std::move(detour);
          ++out.detours;
          detoured = true;
        } else if (Stopped(options.limits)) {
          return fail(o, found.error());
        }
      }
      if (!detoured) ++s.failed_detours;
    }
    // s73, the delay: wait at the start.
    if (!detoured) {
      if (s.delay + options.delay_step > options.max_delay + 1e-9) {
        char cap[32];
        std::snprintf(cap, sizeof cap, "%g", options.max_delay);
        return Unreachable("motion conflicts: robot " + std::to_string(o) + " cannot wait past " + cap +
                           " s nor detour, at " + Describe(*c));
      }
      s.delay += options.delay_step;
      ++out.delays;
    }
    paths[o] = TimeMotionPath(s.path, s.delay, options.timing);
    if (options.on_round) options.on_round(*c, static_cast<int>(o), detoured);
  }
  if (Status ok = CheckTimedMotionPaths(paths, footprints, options.conflicts); !ok.ok()) {
    return Error{ok.error().code, "motion conflicts: final check: " + ok.error().message};
  }
  out.paths = std::move(paths);
  return out;
}

}  // namespace dispatch::engine
