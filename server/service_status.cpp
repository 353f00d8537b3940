#include "server/service_status.h"

namespace dispatch::server {

ServiceStatus FromEngineError(const engine::Error& error) {
  switch (error.code) {
    case engine::ErrorCode::kInvalidArgument:
    case engine::ErrorCode::kNotFound:
    case engine::ErrorCode::kUnreachable:
      return MakeStatus(StatusCode::kInvalidArgument, error.message);
    case engine::ErrorCode::kFailedPrecondition:
      return MakeStatus(StatusCode::kFailedPrecondition, error.message);
    case engine::ErrorCode::kIoError:
      return MakeStatus(StatusCode::kUnavailable, "storage failed: " + error.message);
  }
  return MakeStatus(StatusCode::kInternal, error.message);
}

}  // namespace dispatch::server
