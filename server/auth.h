// Bearer tokens with roles (issue 18 §2, SPEC §4 "Operations"): who may call what.
//
// A token file (`--auth-tokens FILE`) lists tokens by the SHA-256 of their secret, never the
// secrets themselves:
//   {"tokens": [{"name": "wms-1", "role": "wms", "sha256": "<64 hex digits>"},
//               {"name": "r1", "role": "robot", "robot_id": "R1", "sha256": "..."}]}
// Roles and what they may do (Permits):
//   wms       submit, get, list, watch, cancel and explain orders; read the map
//   operator  read everything (orders, robots, traffic, status, metrics, the map), cancel
//             orders, robot commands
//   robot     its own robot stream only (FleetService.Connect as `robot_id`), read the map
//   admin     everything
// A request carries `authorization: Bearer <secret>` (gRPC metadata, or the HTTP header).
// No token, or one the file does not hold -> kUnauthenticated; a known token whose role may
// not do it -> kPermissionDenied; both say which. With no token file everything is allowed
// (the anonymous admin), as before issue 18.
//
// Thread-safe: the token set is swapped whole on Reload (SIGHUP), readers never lock across
// a request.
#pragma once

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>

#include "engine/common/result.h"
#include "server/service_status.h"

namespace dispatch::server {

enum class Role { kWms, kOperator, kRobot, kAdmin };

// What a request does (one per RPC or REST endpoint family).
enum class Access {
  kSubmitOrder,
  kReadOrders,    // get, list, watch, explain
  kCancelOrder,
  kReadFleet,     // status, robots, traffic, zones, intersections
  kReadMap,
  kMetrics,
  kRobotCommand,  // operator commands on robots
  kRobotStream,   // FleetService.Connect
};

const char* RoleName(Role role);
std::optional<Role> ParseRole(std::string_view name);
const char* AccessName(Access access);
bool Permits(Role role, Access access);

// Who made a request: the token's name and role (and, for a robot token, its robot id).
struct Principal {
  std::string name;  // "" when authentication is off
  Role role = Role::kAdmin;
  std::string robot_id;
};

// The tokens of one token file, by the hex SHA-256 of their secret.
class TokenSet {
 public:
  // Errors (kInvalidArgument) name the token and field: not JSON, duplicate or unknown keys,
  // missing name, unknown role, a sha256 that is not 64 hex digits, a robot token without
  // robot_id (or another role with one), two tokens with one name or one hash.
  static engine::Result<TokenSet> Parse(const std::string& json);
  static engine::Result<TokenSet> Load(const std::string& path);
  const Principal* Find(std::string_view secret) const;
  std::size_t size() const { return by_hash_.size(); }

 private:
  std::unordered_map<std::string, Principal> by_hash_;
};

// Lower-case hex SHA-256 of `data` (OpenSSL).
std::string Sha256Hex(std::string_view data);

class Authenticator {
 public:
  // Off: every request is the anonymous admin.
  Authenticator() = default;
  // From a token file; errors as TokenSet::Load.
  static engine::Result<std::unique_ptr<Authenticator>> FromFile(const std::string& path);
  bool enabled() const { return !path_.empty(); }
  // Re-reads the token file. On an error the tokens in force stay.
  engine::Status Reload();
  std::size_t token_count() const;

  // `authorization`: the header's value (nullopt: no header). The principal, or
  // kUnauthenticated / kPermissionDenied with a message saying why.
  struct Outcome {
    ServiceStatus status;
    Principal principal;
  };
  Outcome Authorize(const std::optional<std::string_view>& authorization, Access access) const;

 private:
  std::string path_;
  mutable std::mutex mu_;  // guards tokens_ (the pointer; the set is immutable)
  std::shared_ptr<const TokenSet> tokens_;
};

}  // namespace dispatch::server
