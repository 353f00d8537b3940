// ServerConfig: everything dispatchd is started with (SPEC §4 "Operations"), from flags and an
// optional JSON config file with the same keys (flags win). Plain value; validate with
// ValidateServerConfig. Thread-safe to share once built.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "engine/common/result.h"

namespace dispatch::server {

struct ServerConfig {
  // Address both listeners bind. "" (the default): secure by default (issue 18 §1), 0.0.0.0
  // with TLS, else 127.0.0.1 (loopback only; the log says so). EffectiveBind says which.
  std::string bind;
  int grpc_port = 50051;          // 0 = pick a free port
  int http_port = 8080;           // 0 = pick a free port
  std::string db = "dispatch.db"; // SQLite file
  std::string map = "chu2024";    // chu2024 | wang2019 | <file>.json | <file>.map
  std::string strategy = "auction";  // auction | greedy | exact | psoga (MakeAllocator)
  // Dispatcher seconds between the starts of two allocation rounds at least (0: a round as soon
  // as one is due): orders arriving meanwhile are allocated together, one batch for the batch
  // strategies (exact, psoga).
  double batch_window = 0.0;
  // Orders a robot may hold and still bid for another (0: no limit, the paper's auction), and
  // for a formation order (0: no limit), and one formation at a time heading for a first
  // pick: see AllocationConfig::max_queue, formation_max_queue and
  // CoreOptions::one_formation_per_pick (README "Formations on the dispatch core").
  int max_queue = 0;
  int formation_max_queue = 1;
  bool one_formation_per_pick = true;
  double zeta = 100.0;            // Chu2024 eq. (5) traffic weight
  // How awards get their routes (AllocationConfig::planner): rules | time-windows (Wang2019's
  // time windows for single-robot orders) | conflict-elimination (BIT2024 step 7 in the same
  // windows). turn_time: seconds per 90 degrees of turning in plan
  // ETAs, route costs and the time-window planner (AllocationConfig::turn_time).
  std::string planner = "rules";
  double turn_time = 0.0;
  // Seconds a robot works at an order's drop (AllocationConfig::drop_time): unset (default)
  // = the order's own t_w, as at a pick; 0 = the seed's model (Chu2024 eq. (3) counts the
  // picks only).
  std::optional<double> drop_time;
  // The rules planner's routes (AllocationConfig::routing): floyd | heat (Wang2019 path heat,
  // lanes' use counted over heat_period seconds).
  std::string routing = "floyd";
  double heat_period = 60.0;
  double alpha = 0.5;             // Chu2024 eq. (1) weight of T_t
  double beta = 0.5;              // Chu2024 eq. (1) weight of T_d
  double time_scale = 1.0;        // dispatcher seconds per wall-clock second
  double heartbeat_interval = 1.0;  // wall seconds between robot heartbeats
  double heartbeat_timeout = 5.0;   // wall seconds of silence before a robot is offline
  double offline_grace = 10.0;      // wall seconds offline before its orders are re-allocated
  // Traffic control (SPEC §3.5): release waypoints through the engine's TrafficController
  // (grants, holds, detours); false sends every waypoint released.
  bool traffic_control = true;
  double t_w1 = 10.0;           // s: head-on (single-lane) wait before re-planning (Wang2019)
  double t_w2 = 20.0;           // s: wait on a held point or grant before re-planning
  double blocked_after = 120.0; // s of waiting with no alternative -> robot blocked (fault)
  double blocked_recovery = 60.0;  // s a blocked robot stays in fault (0: until its next Hello)
  // Traffic priority within a class (working, loaded, the rest): index (the lower robot index)
  // or release (the earlier task release, Wang2019 §3.2).
  std::string priority = "index";
  // Wang2019 §3.3 case ①: at a free single-lane corridor a robot gives way to one of higher
  // priority about to enter it from the other end (TrafficControllerConfig::head_on_priority).
  bool head_on_priority = false;
  // Wang2019 §3.3 case ②: a waiting robot met head-on by one of higher priority drives to the
  // nearest free point off its way and waits there (TrafficControllerConfig::head_on_give_way).
  bool head_on_give_way = false;
  // When the traffic gate asks for a robot's next point (TrafficControllerConfig::execution):
  // times, claim or order (Wang2019 §3.2); "" (the default; null in a config file): times with
  // the rules planner, claim with the planned ones (engine::DefaultPlanExecution).
  std::string execution;
  // Bound of the lazy route table's per-destination cache (large grid floors, where a dense
  // all-pairs table does not fit), MiB. It should hold the destinations in use at once (every
  // robot's next stop): on a 38k-cell floor one destination takes 0.46 MB.
  int route_cache_mb = 1024;
  // The route table (engine RouteTableMethod names): floyd | dijkstra | auto (dense tables; a
  // floor above their bound gets the lazy table) | lazy | hub_labels (any pair without a
  // search per destination, memory bounded by its labels: large floors, issue 19).
  std::string route_table = "floyd";
  // Finished orders (completed, cancelled, failed) kept in memory beyond the open ones: the
  // newest this many; older ones are read from the database when asked for (issue 15 §3b).
  int finished_retained = 1000;
  // The dispatch core's journal (issue 15 §4, `dispatch-sim replay --db`): every core input of
  // a run in the database, the newest journal_runs runs kept (0: no journal); recording of a
  // run stops after journal_max_mb MiB (0: no limit). The demo's run (18 robots, 45 s of wall
  // time) wrote 0.66 MB: about 0.9 MB per wall minute, so 512 MiB last some nine hours
  // (README "Replay and what-if").
  int journal_runs = 5;
  int journal_max_mb = 512;
  // Serve the web map's files from this folder instead of the copy built into the binary
  // ("" = built-in; for working on the page without rebuilding).
  std::string web_root;
  std::string ports_file;         // written as {"grpc_port":..,"http_port":..} once listening
  // An inherited file descriptor (e.g. a pipe or FIFO from a script) that gets the same JSON
  // line once listening, then is closed: readiness without polling. -1 = none.
  int ready_fd = -1;
  std::string log_level = "info";  // spdlog level name
  // Transport security (issue 18 §1): gRPC over TLS and REST over HTTPS with this certificate
  // chain and key (PEM files; both or neither). tls_client_ca: robots' streams must present a
  // client certificate issued by this CA whose subject CN (or a SAN) is the robot id of
  // their Hello (mTLS); other clients may connect without one.
  std::string tls_cert;
  std::string tls_key;
  std::string tls_client_ca;
  // Bearer tokens with roles (issue 18 §2, server/auth.h): the token file ("" = no
  // authentication: every caller may do everything). Re-read on SIGHUP. metrics_open: GET
  // /metrics without a token (for a scraper inside the cluster).
  std::string auth_tokens;
  bool metrics_open = false;
};

// The address the listeners bind (see ServerConfig::bind).
std::string EffectiveBind(const ServerConfig& config);

// kInvalidArgument naming the field.
engine::Status ValidateServerConfig(const ServerConfig& config);

// Parses dispatchd's command line (with --config FILE: JSON object with the keys above, e.g.
// {"grpc_port": 0, "db": "/var/lib/dispatch.db"}; flags given on the command line win).
// Returns the config, or an error; `exit_code` >= 0 means "exit now with this code" (e.g.
// --help was printed).
struct ParsedCommandLine {
  ServerConfig config;
  int exit_code = -1;
};
engine::Result<ParsedCommandLine> ParseCommandLine(int argc, char** argv);

}  // namespace dispatch::server
