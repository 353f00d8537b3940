// ServiceStatus -> grpc::Status: the one mapping of service errors onto gRPC codes.
#pragma once

#include <grpcpp/grpcpp.h>

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
  }
  return {grpc::StatusCode::INTERNAL, s.message};
}

}  // namespace dispatch::server
