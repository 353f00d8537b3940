// DispatchServer: dispatchd assembled (SPEC §4): map + route table, store (SQLite, or one a
// test injects), dispatcher loop, gRPC (Order/Fleet/Map services, callback API) and REST.
//
// Start order: load the map, build the route table, open the store, record the map version,
// recover, start the loop, listen (gRPC, then HTTP), write the ports file. Shutdown order:
// HTTP stops; robot and watch streams are finished (UNAVAILABLE "shutting down"); gRPC
// shuts down (in-flight unary calls still get their answers from the loop, a short deadline
// cancels the rest); the loop stops; the store closes. Every acknowledged write is already
// committed, so the database is consistent at any point. Shutdown is idempotent and
// thread-safe; the destructor calls it.
#pragma once

#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "engine/common/result.h"
#include "server/db_lock.h"
#include "server/config.h"
#include "storage/journal_store.h"
#include "storage/store.h"

namespace grpc {
class Server;
}

namespace dispatch::server {

class Dispatcher;
class RestServer;
class OrderServiceImpl;
class FleetServiceImpl;
class MapServiceImpl;
class OperatorServiceImpl;
class ServiceMetrics;
class MeteredStore;
class Authenticator;

struct ServerPorts {
  int grpc = 0;
  int http = 0;
};

class DispatchServer {
 public:
  // `store` (optional, must outlive the server) replaces the SQLite file of config.db (and then
  // no core journal is kept).
  static engine::Result<std::unique_ptr<DispatchServer>> Start(const ServerConfig& config,
                                                               storage::Store* store = nullptr);
  ~DispatchServer();
  DispatchServer(const DispatchServer&) = delete;
  DispatchServer& operator=(const DispatchServer&) = delete;

  ServerPorts ports() const { return ports_; }
  Dispatcher& dispatcher() { return *dispatcher_; }
  void Shutdown();
  // Re-reads the token file (SIGHUP); on an error the tokens in force stay (and it is logged).
  engine::Status ReloadTokens();

 private:
  DispatchServer() = default;

  std::optional<DatabaseLock> db_lock_;  // config.db's, when the server opens it itself
  std::unique_ptr<storage::Store> owned_store_;
  std::unique_ptr<ServiceMetrics> metrics_;
  std::unique_ptr<MeteredStore> metered_store_;  // wraps the store; store_ points here
  storage::Store* store_ = nullptr;
  std::unique_ptr<storage::JournalStore> journal_;  // the core's journal (config.db), if kept
  std::unique_ptr<Dispatcher> dispatcher_;
  std::unique_ptr<Authenticator> auth_;  // before the services, which hold a reference
  std::unique_ptr<OrderServiceImpl> order_service_;
  std::unique_ptr<FleetServiceImpl> fleet_service_;
  std::unique_ptr<MapServiceImpl> map_service_;
  std::unique_ptr<OperatorServiceImpl> operator_service_;
  std::unique_ptr<grpc::Server> grpc_;
  std::unique_ptr<RestServer> rest_;
  ServerPorts ports_;
  std::mutex shutdown_mu_;  // serialises Shutdown
  bool shut_down_ = false;
};

// FNV-1a 64 of the map's JSON encoding, 16 hex digits: the map version tag.
std::string MapContentHash(const std::string& map_json);
// The tag servers before 2026-12 stored: FNV-1a with an offset basis a digit short of the
// standard one. A latest map version stored under it is the same map (RecordMapVersion
// re-tags it), so an upgrade records no new map version.
inline constexpr std::uint64_t kLegacyMapHashBasis = 1469598103934665603ull;
std::string LegacyMapContentHash(const std::string& map_json);

}  // namespace dispatch::server
