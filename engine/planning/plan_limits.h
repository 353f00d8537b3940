// How long a planner may run (STYLE.md: every long computation takes a deadline and a cancel
// check). `stop` is polled between units of work (an expansion, a node); it is where a caller
// puts its deadline and its cancel flag (DeadlineCheck below builds one from a clock, so the
// planners themselves read no clock). `max_expansions` bounds the work deterministically
// (0: no bound), for tests and reproducible runs.
#pragma once

#include <chrono>
#include <cstddef>
#include <functional>
#include <utility>

namespace dispatch::engine {

struct PlanLimits {
  std::function<bool()> stop;
  std::size_t max_expansions = 0;

  bool Exhausted(std::size_t expanded) const {
    return (max_expansions > 0 && expanded >= max_expansions) || (stop && stop());
  }
};

// A stop check that turns true `budget` after it is made, or when `cancelled` does.
inline std::function<bool()> DeadlineCheck(std::chrono::steady_clock::duration budget,
                                           std::function<bool()> cancelled = {}) {
  const auto deadline = std::chrono::steady_clock::now() + budget;
  return [deadline, cancelled = std::move(cancelled)] {
    return std::chrono::steady_clock::now() >= deadline || (cancelled && cancelled());
  };
}

}  // namespace dispatch::engine
