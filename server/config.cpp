#include "server/config.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <algorithm>
#include <functional>
#include <sstream>

#include "engine/dispatch/strategy.h"
#include "engine/routing/route_table.h"
#include "engine/traffic/traffic_controller.h"

namespace dispatch::server {
namespace {

using engine::InvalidArgument;

// One config key: its flag and how to read it from JSON into a config.
struct Key {
  const char* name;  // JSON key; the flag is "--" + name with '_' -> '-'
  std::function<void(const nlohmann::json&, ServerConfig&)> from_json;
  std::function<nlohmann::json(const ServerConfig&)> to_json;
};

template <class T>
Key MakeKey(const char* name, T ServerConfig::*member) {
  return {name, [member](const nlohmann::json& j, ServerConfig& c) { c.*member = j.get<T>(); },
          [member](const ServerConfig& c) { return nlohmann::json(c.*member); }};
}

std::vector<Key> Keys() {
  return {
      MakeKey("bind", &ServerConfig::bind),
      MakeKey("grpc_port", &ServerConfig::grpc_port),
      MakeKey("http_port", &ServerConfig::http_port),
      MakeKey("db", &ServerConfig::db),
      MakeKey("map", &ServerConfig::map),
      MakeKey("strategy", &ServerConfig::strategy),
      MakeKey("batch_window", &ServerConfig::batch_window),
      MakeKey("max_queue", &ServerConfig::max_queue),
      MakeKey("formation_max_queue", &ServerConfig::formation_max_queue),
      MakeKey("one_formation_per_pick", &ServerConfig::one_formation_per_pick),
      MakeKey("zeta", &ServerConfig::zeta),
      MakeKey("planner", &ServerConfig::planner),
      MakeKey("turn_time", &ServerConfig::turn_time),
      {"drop_time",  // a number, or null: the order's own t_w (the default)
       [](const nlohmann::json& j, ServerConfig& c) {
         c.drop_time = j.is_null() ? std::nullopt : std::optional<double>(j.get<double>());
       },
       [](const ServerConfig& c) { return c.drop_time ? nlohmann::json(*c.drop_time) : nlohmann::json(nullptr); }},
      MakeKey("routing", &ServerConfig::routing),
      MakeKey("heat_period", &ServerConfig::heat_period),
      MakeKey("alpha", &ServerConfig::alpha),
      MakeKey("beta", &ServerConfig::beta),
      MakeKey("time_scale", &ServerConfig::time_scale),
      MakeKey("heartbeat_interval", &ServerConfig::heartbeat_interval),
      MakeKey("heartbeat_timeout", &ServerConfig::heartbeat_timeout),
      MakeKey("offline_grace", &ServerConfig::offline_grace),
      MakeKey("traffic_control", &ServerConfig::traffic_control),
      MakeKey("t_w1", &ServerConfig::t_w1),
      MakeKey("t_w2", &ServerConfig::t_w2),
      MakeKey("blocked_after", &ServerConfig::blocked_after),
      MakeKey("blocked_recovery", &ServerConfig::blocked_recovery),
      MakeKey("priority", &ServerConfig::priority),
      MakeKey("head_on_priority", &ServerConfig::head_on_priority),
      MakeKey("head_on_give_way", &ServerConfig::head_on_give_way),
      {"execution",  // a name, or null: the planner's default
       [](const nlohmann::json& j, ServerConfig& c) { c.execution = j.is_null() ? std::string() : j.get<std::string>(); },
       [](const ServerConfig& c) { return c.execution.empty() ? nlohmann::json(nullptr) : nlohmann::json(c.execution); }},
      MakeKey("route_cache_mb", &ServerConfig::route_cache_mb),
      MakeKey("route_table", &ServerConfig::route_table),
      MakeKey("finished_retained", &ServerConfig::finished_retained),
      MakeKey("journal_runs", &ServerConfig::journal_runs),
      MakeKey("journal_max_mb", &ServerConfig::journal_max_mb),
      MakeKey("web_root", &ServerConfig::web_root),
      MakeKey("tls_cert", &ServerConfig::tls_cert),
      MakeKey("tls_key", &ServerConfig::tls_key),
      MakeKey("tls_client_ca", &ServerConfig::tls_client_ca),
      MakeKey("auth_tokens", &ServerConfig::auth_tokens),
      MakeKey("metrics_open", &ServerConfig::metrics_open),
      MakeKey("ports_file", &ServerConfig::ports_file),
      MakeKey("ready_fd", &ServerConfig::ready_fd),
      MakeKey("log_level", &ServerConfig::log_level),
  };
}

std::string FlagName(const char* key) {
  std::string flag = std::string("--") + key;
  for (char& c : flag) {
    if (c == '_') c = '-';
  }
  return flag;
}

engine::Status ApplyConfigFile(const std::string& path, ServerConfig& config) {
  std::ifstream in(path);
  if (!in) return InvalidArgument("cannot read config file '" + path + "'");
  nlohmann::json j;
  try {
    in >> j;
  } catch (const nlohmann::json::exception& e) {
    return InvalidArgument("config file '" + path + "' is not JSON: " + e.what());
  }
  if (!j.is_object()) return InvalidArgument("config file '" + path + "' must hold a JSON object");
  const auto keys = Keys();
  for (const auto& item : j.items()) {
    const std::string& name = item.key();  // (not a structured binding: clang 14 lambdas cannot capture one)
    const auto& value = item.value();
    auto it = std::find_if(keys.begin(), keys.end(), [&](const Key& k) { return name == k.name; });
    if (it == keys.end()) {
      return InvalidArgument("config file '" + path + "': unknown key '" + name + "'");
    }
    try {
      it->from_json(value, config);
    } catch (const nlohmann::json::exception&) {
      return InvalidArgument("config file '" + path + "': key '" + name + "' has the wrong type (" +
                             value.dump() + ")");
    }
  }
  return engine::Ok{};
}

}  // namespace

std::string EffectiveBind(const ServerConfig& c) {
  if (!c.bind.empty()) return c.bind;
  return c.tls_cert.empty() ? "127.0.0.1" : "0.0.0.0";
}

engine::Status ValidateServerConfig(const ServerConfig& c) {
  auto port_ok = [](int p) { return p >= 0 && p <= 65535; };
  if (!port_ok(c.grpc_port)) return InvalidArgument("grpc_port must be in 0..65535");
  if (c.ready_fd < -1 || c.ready_fd == 0 || c.ready_fd == 1 || c.ready_fd == 2) {
    return InvalidArgument("ready_fd must be -1 (none) or an inherited descriptor >= 3");
  }
  if (!port_ok(c.http_port)) return InvalidArgument("http_port must be in 0..65535");
  if (c.tls_cert.empty() != c.tls_key.empty()) return InvalidArgument("tls_cert and tls_key go together");
  if (!c.tls_client_ca.empty() && c.tls_cert.empty()) {
    return InvalidArgument("tls_client_ca needs tls_cert and tls_key (client certificates come with TLS)");
  }
  for (auto [name, path] : {std::pair{"tls_cert", &c.tls_cert}, {"tls_key", &c.tls_key},
                            {"tls_client_ca", &c.tls_client_ca}, {"auth_tokens", &c.auth_tokens}}) {
    if (!path->empty() && !std::filesystem::is_regular_file(*path)) {
      return InvalidArgument(std::string(name) + " '" + *path + "' is not a readable file");
    }
  }
  if (c.db.empty()) return InvalidArgument("db must name a SQLite file");
  if (auto strategy = engine::MakeAllocator(c.strategy); !strategy.ok()) return strategy.error();
  if (!engine::ParsePlanner(c.planner)) {
    std::string names;
    for (const std::string& n : engine::PlannerNames()) names += (names.empty() ? "" : ", ") + n;
    return InvalidArgument("planner must be one of " + names + ", got '" + c.planner + "'");
  }
  if (!c.execution.empty() && !engine::ParsePlanExecution(c.execution)) {
    return InvalidArgument("execution must be times, claim or order, got '" + c.execution + "'");
  }
  if (c.priority != "index" && c.priority != "release") {
    return InvalidArgument("priority must be index or release, got '" + c.priority + "'");
  }
  if (!engine::ParseRouting(c.routing)) {
    return InvalidArgument("routing must be floyd or heat, got '" + c.routing + "'");
  }
  if (!std::isfinite(c.heat_period) || c.heat_period <= 0) return InvalidArgument("heat_period must be > 0 seconds");
  if (!std::isfinite(c.batch_window) || c.batch_window < 0) return InvalidArgument("batch_window must be >= 0 seconds");
  for (auto [name, v] : {std::pair{"zeta", c.zeta}, {"alpha", c.alpha}, {"beta", c.beta}, {"turn_time", c.turn_time},
                         {"drop_time", c.drop_time.value_or(0.0)}}) {
    if (!std::isfinite(v) || v < 0) return InvalidArgument(std::string(name) + " must be finite and >= 0");
  }
  auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  if (!positive(c.time_scale)) return InvalidArgument("time_scale must be > 0");
  if (!positive(c.heartbeat_interval)) return InvalidArgument("heartbeat_interval must be > 0");
  if (!positive(c.heartbeat_timeout) || c.heartbeat_timeout < c.heartbeat_interval) {
    return InvalidArgument("heartbeat_timeout must be >= heartbeat_interval");
  }
  if (!std::isfinite(c.offline_grace) || c.offline_grace < 0) {
    return InvalidArgument("offline_grace must be >= 0");
  }
  for (auto [name, v] : {std::pair{"t_w1", c.t_w1}, {"t_w2", c.t_w2}, {"blocked_after", c.blocked_after}}) {
    if (!positive(v)) return InvalidArgument(std::string(name) + " must be > 0 seconds");
  }
  if (!(c.blocked_recovery >= 0.0) || !std::isfinite(c.blocked_recovery)) {
    return InvalidArgument("blocked_recovery must be >= 0 seconds (0: a blocked robot stays in fault)");
  }
  if (c.route_cache_mb < 1) return InvalidArgument("route_cache_mb must be >= 1");
  if (auto method = engine::ParseRouteTableMethod(c.route_table); !method.ok()) {
    return InvalidArgument("route_table: " + method.error().message);
  }
  if (c.finished_retained < 0) return InvalidArgument("finished_retained must be >= 0");
  if (c.max_queue < 0) return InvalidArgument("max_queue must be >= 0 (0: no limit)");
  if (c.formation_max_queue < 0) return InvalidArgument("formation_max_queue must be >= 0 (0: no limit)");
  if (c.journal_runs < 0) return InvalidArgument("journal_runs must be >= 0 (0: no journal)");
  if (c.journal_max_mb < 0) return InvalidArgument("journal_max_mb must be >= 0 (0: no limit)");
  if (!c.web_root.empty() && !std::filesystem::is_directory(c.web_root)) {
    return InvalidArgument("web_root '" + c.web_root + "' is not a folder");
  }
  return engine::Ok{};
}

engine::Result<ParsedCommandLine> ParseCommandLine(int argc, char** argv) {
  CLI::App app{"dispatchd: warehouse robot dispatch service (gRPC + REST)"};
  ServerConfig flags;
  std::string config_file;
  app.add_option("--config", config_file, "JSON config file with the same keys as the flags");
  app.add_option("--bind", flags.bind,
                 "Address to listen on (default: 0.0.0.0 with TLS, else 127.0.0.1 only)");
  app.add_option("--grpc-port", flags.grpc_port, "gRPC port (0 = any free port)")->capture_default_str();
  app.add_option("--http-port", flags.http_port, "REST port (0 = any free port)")->capture_default_str();
  app.add_option("--db", flags.db, "SQLite database file")->capture_default_str();
  app.add_option("--map", flags.map, "chu2024 | wang2019 | map.json | MovingAI .map")->capture_default_str();
  app.add_option("--strategy", flags.strategy, "auction | greedy | exact | psoga")->capture_default_str();
  app.add_option("--batch-window", flags.batch_window,
                 "Dispatcher s between allocation rounds at least (0: a round as soon as one is due)")
      ->capture_default_str();
  app.add_option("--zeta", flags.zeta, "Traffic weight (Chu2024 eq. 5)")->capture_default_str();
  app.add_option("--planner", flags.planner,
                 "rules | time-windows (Wang2019) | conflict-elimination (BIT2024 step 7)")
      ->capture_default_str();
  app.add_option("--turn-time", flags.turn_time, "Turning time per 90 degrees, s (plans, route costs)")
      ->capture_default_str();
  app.add_option("--drop-time", flags.drop_time,
                 "Seconds a robot works at an order's drop (default: the order's t_w; 0: the seed's "
                 "model, Chu2024 eq. 3 counts the picks only)");
  app.add_option("--priority", flags.priority, "Traffic priority within a class: index | release (Wang2019)")
      ->capture_default_str();
  app.add_option("--head-on-priority", flags.head_on_priority,
                 "Give way at a free corridor to a higher-priority robot about to enter it (Wang2019 case 1)")
      ->capture_default_str();
  app.add_option("--head-on-give-way", flags.head_on_give_way,
                 "A waiting robot met head-on by a higher-priority one drives off its way (Wang2019 case 2)")
      ->capture_default_str();
  app.add_option("--execution", flags.execution,
                 "When a robot asks for its next point: times | claim | order (Wang2019 3.2); default: times "
                 "with the rules planner, claim with the others");
  app.add_option("--routing", flags.routing, "floyd | heat (Wang2019 path heat, rules planner)")->capture_default_str();
  app.add_option("--heat-period", flags.heat_period, "Path heat: the period δ the lanes' use is counted over, s")
      ->capture_default_str();
  app.add_option("--alpha", flags.alpha, "Weight of T_t (Chu2024 eq. 1)")->capture_default_str();
  app.add_option("--beta", flags.beta, "Weight of T_d (Chu2024 eq. 1)")->capture_default_str();
  app.add_option("--time-scale", flags.time_scale, "Dispatcher seconds per wall second")
      ->capture_default_str();
  app.add_option("--heartbeat-interval", flags.heartbeat_interval, "Robot heartbeat period, s")
      ->capture_default_str();
  app.add_option("--heartbeat-timeout", flags.heartbeat_timeout, "Silence before offline, s")
      ->capture_default_str();
  app.add_option("--offline-grace", flags.offline_grace,
                 "Seconds offline before a robot's orders are re-allocated")
      ->capture_default_str();
  app.add_option("--traffic-control", flags.traffic_control,
                 "Release waypoints through the traffic controller (grants, holds, detours)")
      ->capture_default_str();
  app.add_option("--t-w1", flags.t_w1, "Head-on wait before re-planning, dispatcher s")->capture_default_str();
  app.add_option("--t-w2", flags.t_w2, "Wait on a held point before re-planning, dispatcher s")
      ->capture_default_str();
  app.add_option("--blocked-after", flags.blocked_after,
                 "Waiting with no alternative this long marks a robot blocked, dispatcher s")
      ->capture_default_str();
  app.add_option("--blocked-recovery", flags.blocked_recovery,
                 "A blocked robot is back in service after this long in fault, dispatcher s (0: after its next Hello)")
      ->capture_default_str();
  app.add_option("--route-cache-mb", flags.route_cache_mb,
                 "Lazy route table cache bound, MiB (large grid floors)")->capture_default_str();
  app.add_option("--route-table", flags.route_table,
                 "floyd | dijkstra | auto | lazy | hub_labels (large floors: no search per destination)")
      ->capture_default_str();
  app.add_option("--finished-retained", flags.finished_retained,
                 "Finished orders kept in memory (the newest); older ones are read from the database")
      ->capture_default_str();
  app.add_option("--max-queue", flags.max_queue, "Orders a robot may hold and still bid for another (0: no limit)")
      ->capture_default_str();
  app.add_option("--formation-max-queue", flags.formation_max_queue,
                 "Orders a robot may hold and still join a formation (0: no limit)")
      ->capture_default_str();
  app.add_option("--one-formation-per-pick", flags.one_formation_per_pick,
                 "Allocate a formation only while no other is heading for its first pick")->capture_default_str();
  app.add_option("--journal-runs", flags.journal_runs,
                 "Runs of the dispatch core's journal kept in the database for replay (0: no journal)")
      ->capture_default_str();
  app.add_option("--journal-max-mb", flags.journal_max_mb,
                 "Recording of a run stops after this many MiB of journal (0: no limit)")->capture_default_str();
  app.add_option("--web-root", flags.web_root,
                 "Serve the web map from this folder instead of the built-in copy");
  app.add_option("--ports-file", flags.ports_file, "Write the chosen ports as JSON here");
  app.add_option("--ready-fd", flags.ready_fd,
                 "Write the chosen ports as one JSON line to this inherited fd, then close it");
  app.add_option("--tls-cert", flags.tls_cert, "TLS certificate chain (PEM): gRPC over TLS, REST over HTTPS");
  app.add_option("--tls-key", flags.tls_key, "TLS private key (PEM)");
  app.add_option("--tls-client-ca", flags.tls_client_ca,
                 "CA (PEM) of robots' client certificates: a robot's certificate must name its robot id");
  app.add_option("--auth-tokens", flags.auth_tokens,
                 "Token file (JSON, SHA-256 of each secret, with roles): bearer tokens required");
  app.add_option("--metrics-open", flags.metrics_open, "GET /metrics without a token")->capture_default_str();
  app.add_option("--log-level", flags.log_level, "trace|debug|info|warn|error")->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    ParsedCommandLine out;
    out.exit_code = app.exit(e);
    return out;
  }

  ParsedCommandLine out;
  if (!config_file.empty()) {
    auto applied = ApplyConfigFile(config_file, out.config);
    if (!applied.ok()) return applied.error();
  }
  // Flags given on the command line override the file.
  for (const Key& key : Keys()) {
    if (app.get_option(FlagName(key.name))->count() > 0) key.from_json(key.to_json(flags), out.config);
  }
  auto valid = ValidateServerConfig(out.config);
  if (!valid.ok()) return valid.error();
  return out;
}

}  // namespace dispatch::server
