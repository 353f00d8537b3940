#include "server/auth.h"

#include <nlohmann/json.hpp>
#include <openssl/evp.h>

#include <array>
#include <cctype>
#include <fstream>
#include <set>
#include <sstream>
#include <vector>

#include "engine/common/text.h"
#include "formats/json_keys.h"

namespace dispatch::server {
namespace {

using engine::InvalidArgument;

// A secret longer than this is no token of ours (and is not hashed).
constexpr std::size_t kMaxSecret = 4096;
constexpr std::size_t kMaxName = 128;

bool IsHex64(const std::string& s) {
  if (s.size() != 64) return false;
  for (char c : s) {
    if (!std::isxdigit(static_cast<unsigned char>(c))) return false;
  }
  return true;
}

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// "Bearer <secret>" (the scheme case-insensitive, RFC 6750); nullopt when not that form.
std::optional<std::string_view> BearerSecret(std::string_view header) {
  constexpr std::string_view kScheme = "bearer ";
  if (header.size() <= kScheme.size()) return std::nullopt;
  for (std::size_t i = 0; i < kScheme.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(header[i])) != kScheme[i]) return std::nullopt;
  }
  std::string_view secret = header.substr(kScheme.size());
  while (!secret.empty() && secret.front() == ' ') secret.remove_prefix(1);
  while (!secret.empty() && (secret.back() == ' ' || secret.back() == '\r' || secret.back() == '\n')) {
    secret.remove_suffix(1);
  }
  if (secret.empty()) return std::nullopt;
  return secret;
}

}  // namespace

const char* RoleName(Role role) {
  switch (role) {
    case Role::kWms: return "wms";
    case Role::kOperator: return "operator";
    case Role::kRobot: return "robot";
    case Role::kAdmin: return "admin";
  }
  return "?";
}

std::optional<Role> ParseRole(std::string_view name) {
  for (Role r : {Role::kWms, Role::kOperator, Role::kRobot, Role::kAdmin}) {
    if (name == RoleName(r)) return r;
  }
  return std::nullopt;
}

const char* AccessName(Access access) {
  switch (access) {
    case Access::kSubmitOrder: return "submit orders";
    case Access::kReadOrders: return "read orders";
    case Access::kCancelOrder: return "cancel orders";
    case Access::kReadFleet: return "read the fleet's state";
    case Access::kReadMap: return "read the map";
    case Access::kMetrics: return "read the metrics";
    case Access::kRobotCommand: return "send robot commands";
    case Access::kRobotStream: return "connect as a robot";
  }
  return "?";
}

bool Permits(Role role, Access access) {
  switch (role) {
    case Role::kAdmin: return true;
    case Role::kWms:
      return access == Access::kSubmitOrder || access == Access::kReadOrders || access == Access::kCancelOrder ||
             access == Access::kReadMap;
    case Role::kOperator:
      return access == Access::kReadOrders || access == Access::kCancelOrder || access == Access::kReadFleet ||
             access == Access::kReadMap || access == Access::kMetrics || access == Access::kRobotCommand;
    case Role::kRobot: return access == Access::kRobotStream || access == Access::kReadMap;
  }
  return false;
}

std::string Sha256Hex(std::string_view data) {
  std::array<unsigned char, EVP_MAX_MD_SIZE> digest{};
  unsigned int size = 0;
  EVP_Digest(data.data(), data.size(), digest.data(), &size, EVP_sha256(), nullptr);
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(size * 2);
  for (unsigned int i = 0; i < size; ++i) {
    out.push_back(kHex[digest[i] >> 4]);
    out.push_back(kHex[digest[i] & 0xF]);
  }
  return out;
}

engine::Result<TokenSet> TokenSet::Parse(const std::string& text) {
  nlohmann::json j;
  std::optional<std::string> duplicate;
  try {
    j = formats::ParseNotingDuplicateKey(text, &duplicate);
  } catch (const nlohmann::json::exception& e) {
    return InvalidArgument(std::string("the token file is not JSON: ") + e.what());
  }
  // A repeated key would be taken silently (the last one wins): refused.
  if (duplicate) {
    return InvalidArgument("the token file repeats the key '" + engine::Clipped(*duplicate) + "'");
  }
  if (!j.is_object() || !j.contains("tokens") || !j["tokens"].is_array()) {
    return InvalidArgument("the token file must be an object with a \"tokens\" array");
  }
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (it.key() != "tokens") return InvalidArgument("the token file has an unknown key '" + it.key() + "'");
  }
  TokenSet set;
  std::set<std::string> names;
  std::size_t index = 0;
  for (const nlohmann::json& t : j["tokens"]) {
    const std::string where = "token " + std::to_string(index++);
    if (!t.is_object()) return InvalidArgument(where + ": not an object");
    for (auto it = t.begin(); it != t.end(); ++it) {
      const std::string& k = it.key();
      if (k != "name" && k != "role" && k != "sha256" && k != "robot_id") {
        return InvalidArgument(where + ": unknown key '" + k + "' (name, role, sha256, robot_id)");
      }
      if (!it->is_string()) return InvalidArgument(where + ": '" + k + "' must be a string");
    }
    Principal p;
    p.name = t.value("name", "");
    if (p.name.empty() || p.name.size() > kMaxName) {
      return InvalidArgument(where + ": 'name' is required (1 to " + std::to_string(kMaxName) + " characters)");
    }
    const std::string named = where + " '" + p.name + "'";
    if (!names.insert(p.name).second) return InvalidArgument(named + ": the name is used twice");
    const auto role = ParseRole(t.value("role", ""));
    if (!role) return InvalidArgument(named + ": 'role' must be wms, operator, robot or admin");
    p.role = *role;
    p.robot_id = t.value("robot_id", "");
    if (p.role == Role::kRobot && p.robot_id.empty()) {
      return InvalidArgument(named + ": a robot token needs 'robot_id' (the robot it may connect as)");
    }
    if (p.role != Role::kRobot && !p.robot_id.empty()) {
      return InvalidArgument(named + ": only a robot token has a 'robot_id'");
    }
    const std::string hash = Lower(t.value("sha256", ""));
    if (!IsHex64(hash)) {
      return InvalidArgument(named + ": 'sha256' must be the 64 hex digits of the secret's SHA-256 "
                                     "(e.g. printf %s SECRET | sha256sum), not the secret");
    }
    if (!set.by_hash_.emplace(hash, std::move(p)).second) {
      return InvalidArgument(named + ": another token has the same secret");
    }
  }
  return set;
}

engine::Result<TokenSet> TokenSet::Load(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return engine::IoError("cannot read the token file '" + path + "'");
  std::stringstream text;
  text << in.rdbuf();
  auto parsed = Parse(text.str());
  if (!parsed.ok()) return InvalidArgument("token file '" + path + "': " + parsed.error().message);
  return parsed;
}

const Principal* TokenSet::Find(std::string_view secret) const {
  if (secret.size() > kMaxSecret) return nullptr;
  const auto it = by_hash_.find(Sha256Hex(secret));
  return it == by_hash_.end() ? nullptr : &it->second;
}

engine::Result<std::unique_ptr<Authenticator>> Authenticator::FromFile(const std::string& path) {
  auto auth = std::make_unique<Authenticator>();
  auth->path_ = path;
  if (auto loaded = auth->Reload(); !loaded.ok()) return loaded.error();
  return auth;
}

engine::Status Authenticator::Reload() {
  if (path_.empty()) return engine::Ok{};
  auto loaded = TokenSet::Load(path_);
  if (!loaded.ok()) return loaded.error();
  auto set = std::make_shared<const TokenSet>(std::move(loaded).value());
  std::lock_guard<std::mutex> lock(mu_);
  tokens_ = std::move(set);
  return engine::Ok{};
}

std::size_t Authenticator::token_count() const {
  std::lock_guard<std::mutex> lock(mu_);
  return tokens_ ? tokens_->size() : 0;
}

Authenticator::Outcome Authenticator::Authorize(const std::optional<std::string_view>& authorization,
                                                Access access) const {
  Outcome out;
  if (!enabled()) return out;  // the anonymous admin
  std::shared_ptr<const TokenSet> tokens;
  {
    std::lock_guard<std::mutex> lock(mu_);
    tokens = tokens_;
  }
  if (!authorization) {
    out.status = MakeStatus(StatusCode::kUnauthenticated,
                            "authentication required: send 'authorization: Bearer <token>' to " +
                                std::string(AccessName(access)));
    return out;
  }
  const auto secret = BearerSecret(*authorization);
  if (!secret) {
    out.status = MakeStatus(StatusCode::kUnauthenticated, "the authorization header is not 'Bearer <token>'");
    return out;
  }
  const Principal* found = tokens ? tokens->Find(*secret) : nullptr;
  if (!found) {
    out.status = MakeStatus(StatusCode::kUnauthenticated, "unknown or revoked token");
    return out;
  }
  out.principal = *found;
  if (!Permits(found->role, access)) {
    out.status = MakeStatus(StatusCode::kPermissionDenied, "token '" + found->name + "' (role " +
                                                               RoleName(found->role) + ") may not " +
                                                               AccessName(access));
  }
  return out;
}

}  // namespace dispatch::server
