#include "server/server.h"

#include <grpcpp/grpcpp.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include <chrono>

#include <sys/statvfs.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "engine/common/fnv1a.h"
#include "engine/io/map_source.h"
#include "engine/io/map_json.h"
#include "engine/routing/route_table.h"
#include "storage/journal_json.h"
#include "storage/journal_store.h"
#include "server/auth.h"
#include "server/dispatcher.h"
#include "server/fleet_service.h"
#include "server/metered_store.h"
#include "server/metrics.h"
#include "server/operator_service.h"
#include "server/order_service.h"
#include "server/rest_api.h"
#include "storage/sqlite_store.h"

namespace dispatch::server {
namespace {

// Below this much free space on the database's disk dispatchd says it is not ready.
constexpr double kMinFreeDiskMb = 64.0;

std::string PortsJson(const ServerPorts& ports) {
  return nlohmann::json{{"grpc_port", ports.grpc}, {"http_port", ports.http}}.dump() + "\n";
}

// Writes the ports line to an inherited descriptor and closes it (the reader sees EOF).
engine::Status WriteReadyFd(int fd, const ServerPorts& ports) {
  const std::string line = PortsJson(ports);
  std::size_t done = 0;
  while (done < line.size()) {
    const ssize_t n = ::write(fd, line.data() + done, line.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string why = std::strerror(errno);
      ::close(fd);
      return engine::IoError("cannot write the ready line to fd " + std::to_string(fd) + ": " + why);
    }
    done += static_cast<std::size_t>(n);
  }
  ::close(fd);
  return engine::Ok{};
}

engine::Status WritePortsFile(const std::string& path, const ServerPorts& ports) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << PortsJson(ports);
    if (!out) return engine::IoError("cannot write ports file '" + tmp + "'");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    return engine::IoError("cannot rename '" + tmp + "' to '" + path + "'");
  }
  return engine::Ok{};
}

// The core's journal in config.db, with a new run for this start (issue 15 §4).
struct StartedJournal {
  std::unique_ptr<storage::JournalStore> store;
  std::int64_t run = 0;
};
engine::Result<StartedJournal> StartJournal(const ServerConfig& config, const DispatcherOptions& options,
                                            const std::string& map_json, const std::string& map_source) {
  auto opened = storage::JournalStore::Open(config.db);
  if (!opened.ok()) return opened.error();
  storage::RunSetup setup;
  setup.map_json = map_json;
  setup.map_source = map_source;
  setup.strategy = options.strategy;
  setup.allocation = options.allocation;
  setup.core = CoreOptionsOf(options);
  setup.route_cache_bytes = static_cast<std::size_t>(config.route_cache_mb) << 20;
  setup.route_table = config.route_table;
  setup.time_scale = options.time_scale;
  auto encoded = storage::EncodeRunSetup(setup);
  if (!encoded.ok()) return encoded.error();
  const double unix_now = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  auto run = (*opened)->StartRun(unix_now, *encoded, config.journal_runs);
  if (!run.ok()) return run.error();
  spdlog::info("journal: run {} in {} (the newest {} runs kept; dispatch-sim replay --db {})", *run, config.db,
               config.journal_runs, config.db);
  return StartedJournal{std::move(opened).value(), *run};
}

engine::Result<std::string> ReadPem(const std::string& what, const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return engine::IoError("cannot read " + what + " '" + path + "'");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (text.find("-----BEGIN ") == std::string::npos) {
    return engine::InvalidArgument(what + " '" + path + "' is not PEM");
  }
  return text;
}

// gRPC's credentials: TLS from config.tls_cert/key (client certificates requested, and
// verified against tls_client_ca, when given), else plaintext.
engine::Result<std::shared_ptr<grpc::ServerCredentials>> GrpcCredentials(const ServerConfig& config) {
  if (config.tls_cert.empty()) return grpc::InsecureServerCredentials();
  auto cert = ReadPem("tls_cert", config.tls_cert);
  if (!cert.ok()) return cert.error();
  auto key = ReadPem("tls_key", config.tls_key);
  if (!key.ok()) return key.error();
  grpc::SslServerCredentialsOptions options(config.tls_client_ca.empty()
                                                ? GRPC_SSL_DONT_REQUEST_CLIENT_CERTIFICATE
                                                : GRPC_SSL_REQUEST_CLIENT_CERTIFICATE_AND_VERIFY);
  if (!config.tls_client_ca.empty()) {
    auto ca = ReadPem("tls_client_ca", config.tls_client_ca);
    if (!ca.ok()) return ca.error();
    options.pem_root_certs = *ca;
  }
  options.pem_key_cert_pairs.push_back({*key, *cert});
  return grpc::SslServerCredentials(options);
}

}  // namespace

std::string MapContentHash(const std::string& text) { return engine::Hex64(engine::Fnv1a64(text)); }

std::string LegacyMapContentHash(const std::string& text) {
  return engine::Hex64(engine::Fnv1a64(text, kLegacyMapHashBasis));
}

engine::Result<std::unique_ptr<DispatchServer>> DispatchServer::Start(const ServerConfig& config,
                                                                      storage::Store* store) {
  if (auto valid = ValidateServerConfig(config); !valid.ok()) return valid.error();
  spdlog::set_level(spdlog::level::from_str(config.log_level));
  std::unique_ptr<DispatchServer> s(new DispatchServer());

  auto loaded = engine::LoadMapSource(config.map);
  if (!loaded.ok()) return loaded.error();
  auto map = std::make_shared<const engine::WarehouseMap>(std::move(loaded).value());
  engine::AllocationConfig allocation;
  allocation.alpha = config.alpha;
  allocation.beta = config.beta;
  allocation.zeta = config.zeta;
  allocation.max_queue = static_cast<std::size_t>(config.max_queue);
  allocation.formation_max_queue = static_cast<std::size_t>(config.formation_max_queue);
  allocation.planner = engine::ParsePlanner(config.planner).value_or(engine::PlannerKind::kRules);
  allocation.turn_time = config.turn_time;
  allocation.drop_time = config.drop_time;
  allocation.routing = engine::ParseRouting(config.routing).value_or(engine::RoutingKind::kFloyd);
  allocation.heat_period = config.heat_period;
  engine::RouteTableOptions route_options;
  route_options.speed = allocation.speed;
  route_options.turn_penalty_s = allocation.turn_time;
  route_options.lazy_cache_bytes = static_cast<std::size_t>(config.route_cache_mb) << 20;
  auto method = engine::ParseRouteTableMethod(config.route_table);
  if (!method.ok()) return method.error();
  route_options.method = *method;
  auto routes = engine::MakeRouteTable(map, route_options);
  if (!routes.ok()) return routes.error();
  std::shared_ptr<const engine::RouteTable> shared_routes = std::move(routes).value();

  if (store) {
    s->store_ = store;
  } else {
    auto locked = DatabaseLock::Acquire(config.db);
    if (!locked.ok()) return locked.error();
    s->db_lock_.emplace(std::move(locked).value());
    auto opened = storage::SqliteStore::Open(config.db);
    if (!opened.ok()) return opened.error();
    s->owned_store_ = std::move(opened).value();
    s->store_ = s->owned_store_.get();
  }
  s->metrics_ = std::make_unique<ServiceMetrics>();
  s->metered_store_ = std::make_unique<MeteredStore>(*s->store_, *s->metrics_);
  s->store_ = s->metered_store_.get();
  storage::MapVersion version;
  version.name = map->name();
  const std::string map_json = engine::WriteMapJson(*map);
  version.content_hash = MapContentHash(map_json);
  version.also_known_as = {LegacyMapContentHash(map_json)};  // stored by older servers
  version.source = config.map == "chu2024" || config.map == "wang2019" ? "builtin:" + config.map : config.map;
  auto recorded = s->store_->RecordMapVersion(version);
  if (!recorded.ok()) return recorded.error();
  spdlog::info("map '{}' ({} points), version {} ({})", map->name(), map->point_count(),
               recorded->version, recorded->content_hash);

  DispatcherOptions options;
  options.allocation = allocation;
  options.strategy = config.strategy;
  options.batch_window = config.batch_window;
  options.time_scale = config.time_scale;
  options.heartbeat_interval = config.heartbeat_interval;
  options.heartbeat_timeout = config.heartbeat_timeout;
  options.offline_grace = config.offline_grace;
  options.finished_retained = static_cast<std::size_t>(config.finished_retained);
  options.traffic_control = config.traffic_control;
  options.one_formation_per_pick = config.one_formation_per_pick;
  options.blocked_recovery = config.blocked_recovery;
  options.traffic.speed = allocation.speed;
  options.traffic.t_w1 = config.t_w1;
  options.traffic.t_w2 = config.t_w2;
  options.traffic.blocked_after = config.blocked_after;
  options.traffic.priority_by_release = config.priority == "release";
  options.traffic.head_on_priority = config.head_on_priority;
  options.traffic.head_on_give_way = config.head_on_give_way;
  options.traffic.execution =
      engine::ParsePlanExecution(config.execution).value_or(engine::DefaultPlanExecution(allocation.planner));
  options.map_version = recorded->content_hash;
  options.metrics = s->metrics_.get();
  if (!store && config.journal_runs > 0) {
    auto journal = StartJournal(config, options, map_json, version.source);
    if (!journal.ok()) return journal.error();
    s->journal_ = std::move(journal.value().store);
    options.journal = s->journal_.get();
    options.journal_run = journal->run;
    options.journal_max_bytes = static_cast<std::uint64_t>(config.journal_max_mb) << 20;
  }
  auto dispatcher = Dispatcher::Create(map, shared_routes, *s->store_, options);
  if (!dispatcher.ok()) return dispatcher.error();
  s->dispatcher_ = std::move(dispatcher).value();
  s->dispatcher_->Start();

  if (config.auth_tokens.empty()) {
    s->auth_ = std::make_unique<Authenticator>();
  } else {
    auto auth = Authenticator::FromFile(config.auth_tokens);
    if (!auth.ok()) return auth.error();
    s->auth_ = std::move(auth).value();
    spdlog::info("authentication: {} tokens from {} (SIGHUP re-reads it)", s->auth_->token_count(),
                 config.auth_tokens);
  }
  const std::string bind = EffectiveBind(config);
  if (config.tls_cert.empty()) {
    spdlog::warn("no TLS: gRPC and HTTP are plaintext{}", config.bind.empty()
                                                              ? "; listening on loopback only (give --tls-cert and "
                                                                "--tls-key, or --bind, to listen elsewhere)"
                                                              : "");
  }
  if (!s->auth_->enabled()) spdlog::warn("no --auth-tokens: every caller may do everything");
  auto credentials = GrpcCredentials(config);
  if (!credentials.ok()) return credentials.error();

  s->order_service_ = std::make_unique<OrderServiceImpl>(*s->dispatcher_, *s->auth_);
  s->fleet_service_ = std::make_unique<FleetServiceImpl>(*s->dispatcher_, *s->auth_, !config.tls_client_ca.empty());
  s->map_service_ = std::make_unique<MapServiceImpl>(*s->dispatcher_, *s->auth_);
  s->operator_service_ = std::make_unique<OperatorServiceImpl>(*s->dispatcher_, *s->auth_);
  grpc::ServerBuilder builder;
  // One listener per port: a second dispatchd on the same port must fail, not share it.
  builder.AddChannelArgument(GRPC_ARG_ALLOW_REUSEPORT, 0);
  // Connections that never finish their handshake, and connections idle (no stream) for two
  // minutes, are closed: idle clients cannot hold descriptors for ever (issue 18 §3). A
  // client's channel reconnects by itself when it calls again.
  builder.AddChannelArgument(GRPC_ARG_SERVER_HANDSHAKE_TIMEOUT_MS, 10'000);
  builder.AddChannelArgument(GRPC_ARG_MAX_CONNECTION_IDLE_MS, 120'000);
  int grpc_port = 0;
  builder.AddListeningPort(bind + ":" + std::to_string(config.grpc_port), *credentials, &grpc_port);
  builder.RegisterService(s->order_service_.get());
  builder.RegisterService(s->fleet_service_.get());
  builder.RegisterService(s->map_service_.get());
  builder.RegisterService(s->operator_service_.get());
  s->grpc_ = builder.BuildAndStart();
  if (!s->grpc_ || grpc_port == 0) {
    return engine::IoError("cannot listen for gRPC on " + bind + ":" + std::to_string(config.grpc_port));
  }
  s->ports_.grpc = grpc_port;

  RestSecurity security;
  security.tls_cert = config.tls_cert;
  security.tls_key = config.tls_key;
  security.auth = s->auth_.get();
  security.metrics_open = config.metrics_open;
  // Ready while the database takes writes and its disk has room (GET /readyz).
  auto store_health = [metered = s->metered_store_.get(),
                       folder = std::filesystem::absolute(config.db).parent_path().string(),
                       own_file = store == nullptr]() -> std::optional<std::string> {
    if (auto failed = metered->WriteFailure()) return "the database's last write failed: " + *failed;
    struct statvfs disk {};
    if (own_file && ::statvfs(folder.c_str(), &disk) == 0) {
      const double free_mb = static_cast<double>(disk.f_bavail) * static_cast<double>(disk.f_frsize) / 1048576.0;
      if (free_mb < kMinFreeDiskMb) {
        return "the database's disk (" + folder + ") has " + std::to_string(static_cast<int>(free_mb)) +
               " MiB free, under " + std::to_string(static_cast<int>(kMinFreeDiskMb));
      }
    }
    return std::nullopt;
  };
  s->rest_ = std::make_unique<RestServer>(RestHandlers(*s->dispatcher_, s->metrics_.get(), store_health),
                                          config.web_root, security);
  if (!s->rest_->valid()) {
    return engine::InvalidArgument("HTTPS: cannot load the certificate '" + config.tls_cert + "' with the key '" +
                                   config.tls_key + "' (do they match?)");
  }
  const int http_port = s->rest_->Start(bind, config.http_port);
  if (http_port <= 0) {
    return engine::IoError("cannot listen for HTTP on " + bind + ":" + std::to_string(config.http_port));
  }
  s->ports_.http = http_port;
  const char* scheme = config.tls_cert.empty() ? "" : " (TLS)";
  spdlog::info("listening: gRPC{} {}:{}, HTTP{} {}:{}", scheme, bind, grpc_port, config.tls_cert.empty() ? "" : "S",
               bind, http_port);
  if (!config.ports_file.empty()) {
    if (auto written = WritePortsFile(config.ports_file, s->ports_); !written.ok()) return written.error();
    spdlog::info("ports written to {}", config.ports_file);
  }
  if (config.ready_fd >= 0) {
    if (auto written = WriteReadyFd(config.ready_fd, s->ports_); !written.ok()) return written.error();
  }
  return s;
}

DispatchServer::~DispatchServer() { Shutdown(); }

engine::Status DispatchServer::ReloadTokens() {
  if (!auth_ || !auth_->enabled()) return engine::Ok{};
  if (auto reloaded = auth_->Reload(); !reloaded.ok()) {
    spdlog::error("tokens not reloaded (the previous ones stay in force): {}", reloaded.error().message);
    return reloaded;
  }
  spdlog::info("authentication: {} tokens reloaded", auth_->token_count());
  return engine::Ok{};
}

void DispatchServer::Shutdown() {
  std::lock_guard<std::mutex> lock(shutdown_mu_);
  if (shut_down_) return;
  shut_down_ = true;
  if (rest_) rest_->Stop();
  if (dispatcher_) dispatcher_->CloseStreams();
  if (grpc_) {
    grpc_->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(3));
    grpc_->Wait();
  }
  if (dispatcher_) dispatcher_->Stop();
  spdlog::info("dispatchd stopped");
}

}  // namespace dispatch::server
