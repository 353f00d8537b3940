// Text that came from outside (ids, reasons) quoted back in messages and logs: bounded, so a
// 1 MB robot id never travels whole into a status message or a log line (issue 18 §3).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace dispatch::engine {

// `text` itself when it has at most `max_bytes` bytes, else its first `max_bytes` bytes (whole
// UTF-8 characters) and "... (N bytes)".
std::string Clipped(std::string_view text, std::size_t max_bytes = 64);

// `v` with six significant digits and no trailing zeros ("%g", as a stream prints it): 2.5,
// 100, 1e-05. How messages and generated ids write coordinates.
std::string Number(double v);

}  // namespace dispatch::engine
