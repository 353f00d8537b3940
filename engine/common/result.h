// Expected failures as values (STYLE.md: leveldb Status, rmf Planner::Result).
//
// `Error` carries a machine-readable code and a human message that names what was wrong.
// `Result<T>` holds either a T or an Error. Accessing the wrong alternative is a broken
// contract and throws std::logic_error. Values are plain data: not thread-safe to mutate
// concurrently, safe to share once built.
#pragma once

#include <stdexcept>
#include <string>
#include <utility>
#include <variant>

namespace dispatch::engine {

enum class ErrorCode {
  kInvalidArgument,     // malformed input (bad file, bad field, bad value)
  kNotFound,            // unknown id or point
  kUnreachable,         // no route between two points
  kFailedPrecondition,  // the request cannot be served in the current state
  kIoError,             // a file could not be read or written
};

const char* ErrorCodeName(ErrorCode code);

struct Error {
  ErrorCode code = ErrorCode::kInvalidArgument;
  std::string message;
};

inline Error InvalidArgument(std::string message) {
  return {ErrorCode::kInvalidArgument, std::move(message)};
}
inline Error NotFound(std::string message) { return {ErrorCode::kNotFound, std::move(message)}; }
inline Error Unreachable(std::string message) {
  return {ErrorCode::kUnreachable, std::move(message)};
}
inline Error IoError(std::string message) { return {ErrorCode::kIoError, std::move(message)}; }

template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : data_(std::move(value)) {}  // NOLINT: implicit by design
  Result(Error error) : data_(std::move(error)) {}  // NOLINT: implicit by design

  bool ok() const { return std::holds_alternative<T>(data_); }
  explicit operator bool() const { return ok(); }

  const T& value() const& {
    if (!ok()) throw std::logic_error("Result::value() on error: " + error().message);
    return std::get<T>(data_);
  }
  T& value() & {
    if (!ok()) throw std::logic_error("Result::value() on error: " + error().message);
    return std::get<T>(data_);
  }
  T&& value() && {
    if (!ok()) throw std::logic_error("Result::value() on error: " + error().message);
    return std::get<T>(std::move(data_));
  }
  const Error& error() const {
    if (ok()) throw std::logic_error("Result::error() on a value");
    return std::get<Error>(data_);
  }

  const T& operator*() const& { return value(); }
  const T* operator->() const { return &value(); }

 private:
  std::variant<T, Error> data_;
};

// Result<void> stand-in.
struct Ok {};
using Status = Result<Ok>;

}  // namespace dispatch::engine
