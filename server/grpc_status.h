// ServiceStatus -> grpc::Status: the one mapping of service errors onto gRPC codes, and
// Fitted, which keeps status messages short enough for every client.
#pragma once

#include <grpcpp/grpcpp.h>

#include <string>

#include "server/service_status.h"

namespace dispatch::server {

inline grpc::Status ToGrpcStatus(const ServiceStatus& s) {
  switch (s.code) {
    case StatusCode::kOk: return grpc::Status::OK;
    case StatusCode::kInvalidArgument: return {grpc::StatusCode::INVALID_ARGUMENT, s.message};
    case StatusCode::kNotFound: return {grpc::StatusCode::NOT_FOUND, s.message};
    case StatusCode::kAlreadyExists: return {grpc::StatusCode::ALREADY_EXISTS, s.message};
    case StatusCode::kFailedPrecondition: return {grpc::StatusCode::FAILED_PRECONDITION, s.message};
    case StatusCode::kUnavailable: return {grpc::StatusCode::UNAVAILABLE, s.message};
    case StatusCode::kInternal: return {grpc::StatusCode::INTERNAL, s.message};
    case StatusCode::kUnauthenticated: return {grpc::StatusCode::UNAUTHENTICATED, s.message};
    case StatusCode::kPermissionDenied: return {grpc::StatusCode::PERMISSION_DENIED, s.message};
    case StatusCode::kDeadlineExceeded: return {grpc::StatusCode::DEADLINE_EXCEEDED, s.message};
  }
  return {grpc::StatusCode::INTERNAL, s.message};
}

// Status messages travel in a trailer and clients refuse large metadata ("received initial
// metadata size exceeds limit", which would hide the error); messages echo client input (a
// point name, an id), so they are cut to a size every client accepts.
inline grpc::Status Fitted(grpc::Status status) {
  constexpr std::size_t kMaxMessage = 1024;
  const std::string& m = status.error_message();
  if (m.size() <= kMaxMessage) return status;
  std::size_t cut = kMaxMessage;
  while (cut > 0 && (static_cast<unsigned char>(m[cut]) & 0xC0) == 0x80) --cut;  // keep UTF-8 whole
  return {status.error_code(), m.substr(0, cut) + "... (" + std::to_string(m.size()) + " bytes)"};
}

}  // namespace dispatch::server
