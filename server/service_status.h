// ServiceStatus: the outcome of a dispatcher request, in the service's own codes. Engine and
// store errors map onto it in one place (FromEngineError); gRPC and HTTP map from it in one
// place each (grpc_status.h, rest_api.cpp). Plain value.
#pragma once

#include <string>
#include <utility>

#include "engine/common/result.h"

namespace dispatch::server {

enum class StatusCode {
  kOk,
  kInvalidArgument,     // malformed request, unknown point, unreachable stop
  kNotFound,            // unknown order or robot
  kAlreadyExists,       // client order id reused with other content; robot already connected
  kFailedPrecondition,  // not allowed in the current state (e.g. cancel a completed order)
  kUnavailable,         // storage failed (nothing was accepted) or shutting down
  kInternal,            // a broken invariant
  kUnauthenticated,     // no token, or one the server does not know (server/auth.h)
  kPermissionDenied,    // a known token whose role may not do this
  kDeadlineExceeded,    // the caller took too long (a robot stream with no Hello)
};

struct ServiceStatus {
  StatusCode code = StatusCode::kOk;
  std::string message;
  bool ok() const { return code == StatusCode::kOk; }
};

inline ServiceStatus OkStatus() { return {}; }
inline ServiceStatus MakeStatus(StatusCode code, std::string message) {
  return {code, std::move(message)};
}

// Engine/request errors: kInvalidArgument, kNotFound and kUnreachable in a request are the
// caller's fault (INVALID_ARGUMENT, or NOT_FOUND for an unknown order id passed as `kind`);
// kIoError is a storage failure (UNAVAILABLE).
ServiceStatus FromEngineError(const engine::Error& error);

}  // namespace dispatch::server
