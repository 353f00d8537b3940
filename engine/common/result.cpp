#include "engine/common/result.h"

namespace dispatch::engine {

const char* ErrorCodeName(ErrorCode code) {
  switch (code) {
    case ErrorCode::kInvalidArgument: return "invalid_argument";
    case ErrorCode::kNotFound: return "not_found";
    case ErrorCode::kUnreachable: return "unreachable";
    case ErrorCode::kFailedPrecondition: return "failed_precondition";
    case ErrorCode::kIoError: return "io_error";
  }
  return "unknown";
}

}  // namespace dispatch::engine
