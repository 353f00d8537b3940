// Authorization of gRPC calls (server/auth.h): the bearer token from the call's
// `authorization` metadata, and the robot ids a stream's client certificate names (mTLS).
// Thread-safe.
#pragma once

#include <grpcpp/grpcpp.h>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "server/auth.h"

namespace dispatch::server {

inline Authenticator::Outcome AuthorizeCall(const Authenticator& auth, const grpc::ServerContextBase& context,
                                            Access access) {
  const auto& metadata = context.client_metadata();
  std::optional<std::string_view> header;
  if (const auto it = metadata.find("authorization"); it != metadata.end()) {
    header = std::string_view(it->second.data(), it->second.size());
  }
  return auth.Authorize(header, access);
}

// The names a verified client certificate gives its holder: the subject's CN and every
// subject alternative name (empty without a verified certificate).
inline std::vector<std::string> CertificateNames(const grpc::ServerContextBase& context) {
  std::vector<std::string> names;
  const auto auth = context.auth_context();
  if (!auth || !auth->IsPeerAuthenticated()) return names;
  for (const char* property : {"x509_common_name", "x509_subject_alternative_name"}) {
    for (const grpc::string_ref& v : auth->FindPropertyValues(property)) names.emplace_back(v.data(), v.size());
  }
  return names;
}

}  // namespace dispatch::server
