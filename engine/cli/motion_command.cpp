#include "engine/cli/motion_command.h"

#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <sstream>
#include <vector>

#include "engine/io/motion_svg.h"
#include "engine/motion/hybrid_astar.h"
#include "engine/motion/motion_conflict_elimination.h"
#include "engine/motion/motion_conflicts.h"
#include "engine/motion/motion_path_check.h"
#include "engine/motion/narrow_floor.h"

namespace dispatch::engine {
namespace {

struct Query {
  std::string name;
  MotionPose start;
  MotionPose goal;
};

// "x,y,theta" -> a pose; nullopt unless exactly three finite numbers.
std::optional<MotionPose> ParsePose(const std::string& text) {
  std::istringstream in(text);
  double v[3];
  char comma = 0;
  if (!(in >> v[0] >> comma) || comma != ',' || !(in >> v[1] >> comma) || comma != ',' || !(in >> v[2])) {
    return std::nullopt;
  }
  in >> std::ws;
  if (!in.eof() || !std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) return std::nullopt;
  return MotionPose{v[0], v[1], v[2]};
}

}  // namespace

CLI::App* AddMotionCommand(CLI::App& app, MotionArgs& a) {
  auto* m = app.add_subcommand("motion", "4WIS hybrid A* (BIT2024 step 6) vs. the baseline on the narrow floor");
  m->add_option("--from", a.from, "Start pose x,y,theta (m, m, rad); needs --to");
  m->add_option("--to", a.to, "Goal pose x,y,theta; needs --from");
  m->add_option("--svg", a.svg, "Write the grid, paths and footprints to this SVG file");
  m->add_option("--budget-ms", a.budget_ms, "Time budget per plan (with --robots: for step 7), ms")
      ->capture_default_str()->check(CLI::PositiveNumber);
  m->add_option("--robots", a.robots, "Run BIT2024 step 7 for N robots between the floor's stations instead");
  m->add_option("--seed", a.seed, "Seed of the stations' draw and of step 7 (with --robots)")->capture_default_str();
  m->add_flag("--trace", a.trace, "With --robots: print each round of step 7");
  return m;
}

namespace {

// BIT2024 step 7 on the narrow floor: N robots, starts and goals drawn among the stations.
int RunFleet(const MotionArgs& a, const NarrowFloor& floor, const FootprintChecker& checker) {
  for (const MotionPose& p : floor.stations) {
    if (checker.Collides(p)) {
      std::fprintf(stderr, "dispatch-sim: motion: station (%g, %g) collides (a bug)\n", p.x, p.y);
      return 2;
    }
  }
  Result<std::vector<MotionRobot>> drawn_robots = NarrowFloorRobots(floor, a.robots, a.seed);
  if (!drawn_robots.ok()) {
    std::fprintf(stderr, "dispatch-sim: motion: %s\n", drawn_robots.error().message.c_str());
    return 1;
  }
  const std::vector<MotionRobot>& robots = *drawn_robots;
  MotionConflictEliminationOptions options;
  options.seed = a.seed;
  options.planner.min_turn_radius = floor.min_turn_radius;
  const auto budget = std::chrono::duration<double, std::milli>(a.budget_ms);
  if (a.trace) {
    options.on_round = [](const MotionConflict& c, int constrained, bool detoured) {
      std::printf("  round: %s -> robot %d %s\n", Describe(c).c_str(), constrained, detoured ? "detours" : "waits");
    };
  }
  options.limits.stop = DeadlineCheck(std::chrono::duration_cast<std::chrono::steady_clock::duration>(budget));
  std::printf("BIT2024 step 7 on the narrow floor: %zu robots, seed %llu; %.1f m/s, %.1f rad/s, clearance %.2f m, "
              "sampled every %.1f s\n",
              a.robots, static_cast<unsigned long long>(a.seed), options.timing.speed, options.timing.spin_rate,
              options.conflicts.clearance, options.conflicts.time_step);
  const auto t0 = std::chrono::steady_clock::now();
  const auto solved = EliminateMotionConflicts(floor.grid, robots, options);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (!solved.ok()) {
    std::printf("not solved after %.1f ms: %s\n", ms, solved.error().message.c_str());
    return 2;
  }
  const MotionFleetSolution& fleet = solved.value();
  std::printf("%-6s %-20s %-20s %7s %9s %10s %9s\n", "robot", "start", "goal", "wait_s", "length_m", "arrival_s",
              "switches");
  const char* colours[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b"};
  std::vector<MotionSvgPath> drawn;
  for (std::size_t i = 0; i < robots.size(); ++i) {
    const TimedMotionPath& p = fleet.paths[i];
    char start[40], goal[40];
    std::snprintf(start, sizeof start, "(%.2f,%.2f,%.2f)", robots[i].start.x, robots[i].start.y, robots[i].start.theta);
    std::snprintf(goal, sizeof goal, "(%.2f,%.2f,%.2f)", robots[i].goal.x, robots[i].goal.y, robots[i].goal.theta);
    std::printf("%-6zu %-20s %-20s %7.1f %9.2f %10.1f %9d\n", i, start, goal, p.start_time, p.path.length, p.arrival(),
                p.path.switches);
    drawn.push_back({"robot " + std::to_string(i), colours[i % 6], p.path, floor.footprint});
  }
  std::printf("conflict-free (checked every %.1f s): yes; rounds %zu, searches %zu, detours %zu, waits %zu; %.1f ms\n",
              options.conflicts.time_step, fleet.rounds, fleet.searches, fleet.detours, fleet.delays, ms);
  if (!a.svg.empty()) {
    MotionSvgOptions svg;
    svg.title = "BIT2024 step 7: " + std::to_string(a.robots) + " robots, seed " + std::to_string(a.seed);
    std::ofstream out(a.svg);
    out << RenderMotionSvg(floor.grid, drawn, svg);
    out.close();
    if (!out) {
      std::fprintf(stderr, "dispatch-sim: motion: cannot write %s\n", a.svg.c_str());
      return 1;
    }
    std::printf("wrote %s (%zu paths)\n", a.svg.c_str(), drawn.size());
  }
  return 0;
}

}  // namespace

int RunMotion(const MotionArgs& a) {
  const NarrowFloor floor = BuildNarrowFloor();
  const FootprintChecker checker(floor.grid, floor.footprint);
  if (a.robots > 0) {
    if (!a.from.empty() || !a.to.empty()) {
      std::fprintf(stderr, "dispatch-sim: motion: --robots runs step 7 on the floor's stations; drop --from/--to\n");
      return 1;
    }
    return RunFleet(a, floor, checker);
  }
  std::vector<Query> queries;
  if (a.from.empty() != a.to.empty()) {
    std::fprintf(stderr, "dispatch-sim: motion: --from and --to go together\n");
    return 1;
  }
  if (!a.from.empty()) {
    const auto from = ParsePose(a.from);
    const auto to = ParsePose(a.to);
    if (!from || !to) {
      std::fprintf(stderr, "dispatch-sim: motion: a pose is x,y,theta (three numbers), got '%s'\n",
                   (!from ? a.from : a.to).c_str());
      return 1;
    }
    for (const MotionPose& p : {*from, *to}) {
      if (checker.Collides(p)) {
        std::fprintf(stderr, "dispatch-sim: motion: pose (%g, %g, %g) collides on the narrow floor (12 m x 6 m)\n",
                     p.x, p.y, p.theta);
        return 1;
      }
    }
    queries.push_back({"from-to", *from, *to});
  } else {
    queries = {{"crab-slot", floor.crab_start, floor.crab_goal},
               {"dead-end", floor.dead_end_start, floor.dead_end_goal},
               {"cross-floor", floor.cross_start, floor.cross_goal}};
  }
  struct Planner {
    const char* name;
    const char* colour;
    HybridAStarOptions options;
  };
  std::vector<Planner> planners = {{"4wis", "#1f77b4", {}}, {"baseline", "#d62728", {}}};
  planners[1].options.allow_crab = false;
  planners[1].options.allow_spin = false;
  for (Planner& p : planners) p.options.min_turn_radius = floor.min_turn_radius;
  MotionPathCheck check;
  check.radius = floor.min_turn_radius;
  const MotionTiming timing;

  std::printf("narrow floor 12 m x 6 m, robot %.1f m x %.1f m, turning radius %.1f m; time at %.1f m/s, %.1f rad/s\n",
              floor.footprint.length, floor.footprint.width, floor.min_turn_radius, timing.speed, timing.spin_rate);
  std::printf("%-12s %-9s %-14s %9s %8s %9s %11s %9s\n", "query", "planner", "solved", "length_m", "time_s",
              "switches", "expansions", "ms");
  std::vector<MotionSvgPath> drawn;
  int rc = 0;
  for (const Query& q : queries) {
    for (Planner& p : planners) {
      const auto budget = std::chrono::duration<double, std::milli>(a.budget_ms);
      p.options.limits.stop = DeadlineCheck(std::chrono::duration_cast<std::chrono::steady_clock::duration>(budget));
      const auto t0 = std::chrono::steady_clock::now();
      const auto found = PlanHybridAStar(checker, q.start, q.goal, p.options);
      const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      if (!found.ok()) {
        const char* why = found.error().code == ErrorCode::kFailedPrecondition ? "no: stopped"
                          : found.error().code == ErrorCode::kUnreachable      ? "no: unreachable"
                                                                               : "no: invalid";
        std::printf("%-12s %-9s %-14s %9s %8s %9s %11s %9.1f\n", q.name.c_str(), p.name, why, "-", "-", "-", "-", ms);
        continue;
      }
      const MotionPath& path = found.value();
      const Status checked = CheckMotionPath(checker, path, q.start, q.goal, check);
      if (!checked.ok()) rc = 2;
      const double seconds = TimeMotionPath(path, 0.0, timing).arrival();
      std::printf("%-12s %-9s %-14s %9.2f %8.1f %9d %11zu %9.1f%s\n", q.name.c_str(), p.name,
                  checked.ok() ? "yes" : "INVALID", path.length, seconds, path.switches, path.nodes_expanded, ms,
                  checked.ok() ? "" : ("  " + checked.error().message).c_str());
      drawn.push_back({q.name + " " + p.name, p.colour, path, floor.footprint});
    }
  }
  if (!a.svg.empty()) {
    MotionSvgOptions options;
    options.title = "4WIS (blue) vs baseline (red) on the narrow floor";
    std::ofstream out(a.svg);
    out << RenderMotionSvg(floor.grid, drawn, options);
    out.close();
    if (!out) {
      std::fprintf(stderr, "dispatch-sim: motion: cannot write %s\n", a.svg.c_str());
      return 1;
    }
    std::printf("wrote %s (%zu paths)\n", a.svg.c_str(), drawn.size());
  }
  return rc;
}

}  // namespace dispatch::engine
