#include "engine/cli/routing_command.h"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <string>
#include <utility>

#include "engine/sim/routing_comparison.h"

namespace dispatch::engine {

CLI::App* AddRoutingCommand(CLI::App& app, RoutingArgs& a) {
  auto* r = app.add_subcommand("routing", "Seed 004 §4.1-4.2: traditional vs. improved (heat + turning) Dijkstra");
  r->add_option("--tasks", a.tasks, "Task counts (robots = orders), e.g. 4,8,12")->delimiter(',')->capture_default_str()
      ->check(CLI::PositiveNumber);
  r->add_option("--seeds", a.seeds, "Seeds 1..N per task count")->capture_default_str()->check(CLI::PositiveNumber);
  r->add_option("--turn-time", a.turn_time, "Turning time, s per 90 degrees")->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  return r;
}

int RunRouting(const RoutingArgs& a) {
  std::printf("Seed 004 §4.1-4.2: 40 x 30 grid, turning %.1f s per 90 degrees, means per robot over seeds 1-%zu\n",
              a.turn_time, a.seeds);
  std::printf("%6s %13s %13s %11s %11s %12s %12s %9s\n", "tasks", "dist trad m", "dist impr m", "time trad s",
              "time impr s", "total dist", "total time", "orders");
  int status = 0;
  for (std::size_t tasks : a.tasks) {
    RoutingRun trad, impr;
    std::size_t orders = 0;
    for (std::size_t seed = 1; seed <= a.seeds; ++seed) {
      RoutingComparisonOptions o;
      o.tasks = tasks;
      o.seed = seed;
      o.turn_time = a.turn_time;
      auto c = RunRoutingComparison(o);
      if (!c.ok()) {
        std::fprintf(stderr, "dispatch-sim: %s\n", c.error().message.c_str());
        return 1;
      }
      for (auto [sum, run] : {std::pair{&trad, &c->traditional}, std::pair{&impr, &c->improved}}) {
        sum->completed += run->completed;
        sum->total_distance += run->total_distance;
        sum->total_time += run->total_time;
        for (const std::string& f : run->failures) {
          std::fprintf(stderr, "%zu tasks, seed %zu, %s: %s\n", tasks, seed, run == &c->improved ? "improved" : "traditional",
                       f.c_str());
        }
      }
      orders += tasks;
    }
    if (trad.completed != orders || impr.completed != orders) status = 2;
    const double n = static_cast<double>(orders);
    std::printf("%6zu %13.2f %13.2f %11.2f %11.2f %+11.1fm %+11.1fs %4zu/%zu/%zu\n", tasks, trad.total_distance / n,
                impr.total_distance / n, trad.total_time / n, impr.total_time / n,
                (impr.total_distance - trad.total_distance) / static_cast<double>(a.seeds),
                (impr.total_time - trad.total_time) / static_cast<double>(a.seeds), trad.completed, impr.completed,
                orders);
  }
  return status;
}

}  // namespace dispatch::engine
