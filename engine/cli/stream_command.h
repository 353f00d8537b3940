// dispatch-sim stream and compare: order streams on a floor through the dispatch core (its
// allocation rounds and traffic gate, robots following its messages), one run or side by side
// (strategies, or planners x routings). The subcommands' options, the set-up of a run
// (map, route table, robots, orders) and the printed summaries.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace dispatch::engine {

struct StreamArgs {
  std::string map = "chu2024", orders_csv, strategy = "auction", journal;
  std::vector<std::string> orders;  // task tables, submitted together
  std::size_t robots = 18, random = 0, repeat = 1, max_queue = 0, formation_max_queue = 1;
  std::uint64_t seed = 1;
  double interval = 2.0, zeta = 100.0, dt = 0.1, max_time = 36000.0, formations = 0.0;
  bool check_safety = false, one_formation_per_pick = true;
  double blocked_recovery = 60.0;  // CoreOptions::blocked_recovery
  double batch_window = 0.0;       // StreamConfig::allocation_period
  std::vector<std::string> trace;  // robots to trace
  double trace_from = 0.0, trace_to = std::numeric_limits<double>::infinity();
  std::string planner = "rules";           // AllocationConfig::planner
  std::vector<std::string> planners;       // compare: one column per planner (x routing)
  std::string routing = "floyd";           // AllocationConfig::routing
  std::vector<std::string> routings;       // compare: one column per routing (x planner)
  double turn_s = 0.0;                     // turning time per 90 degrees (AllocationConfig::turn_time)
  std::optional<double> drop_s;            // work at a drop (AllocationConfig::drop_time)
  double heat_period = 60.0;               // path heat: δ, s
  std::string priority = "index";          // TrafficControllerConfig::priority_by_release
  bool head_on_priority = false;           // TrafficControllerConfig::head_on_priority
  bool head_on_give_way = false;           // TrafficControllerConfig::head_on_give_way
  std::string execution;                   // TrafficControllerConfig::execution ("": the planner's default)
  std::string route_table = "floyd";       // RouteTableOptions::method (RouteTableMethodNames())
};

struct StreamCommands {
  CLI::App* stream = nullptr;
  CLI::App* compare = nullptr;
};

// Adds `stream` and `compare` to `app`, their options bound to the two argument sets.
StreamCommands AddStreamCommands(CLI::App& app, StreamArgs& stream, StreamArgs& compare);
int RunStream(const StreamArgs& a);
int RunCompare(StreamArgs a);

namespace cli_stream {
// Prints "dispatch-sim: <message>" to stderr; returns 1 (the commands' failure status).
int Fail(const std::string& message);
}  // namespace cli_stream

}  // namespace dispatch::engine
