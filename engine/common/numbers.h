// Numeric constants the engine's files share: one definition each (a unity build compiles
// several files as one, where two private definitions of a name would clash).
#pragma once

#include <limits>

namespace dispatch::engine {

// No route, no bid, no bound yet.
inline constexpr double kInf = std::numeric_limits<double>::infinity();
// The tolerance when comparing times (s) and lengths (m) computed along different paths.
inline constexpr double kEps = 1e-9;

}  // namespace dispatch::engine
