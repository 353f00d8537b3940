// DispatchClock: dispatcher seconds - the time that orders, plans, robot reports and the
// journal carry - read off the steady wall clock. They go on from the latest time the store
// holds (ContinueFrom, at recovery: a restart never turns time back) and run time_scale
// dispatcher seconds per wall second (DispatcherOptions::time_scale).
//
// Not thread-safe to change: the dispatcher's loop owns it (recovery runs before the loop).
#pragma once

#include <algorithm>
#include <chrono>

namespace dispatch::server {

class DispatchClock {
 public:
  using Clock = std::chrono::steady_clock;

  explicit DispatchClock(double time_scale, Clock::time_point wall_start = Clock::now())
      : scale_(time_scale), start_(wall_start) {}

  // Recovery: the clock reads at least `t` from its start on.
  void ContinueFrom(double t) { base_ = std::max(base_, t); }
  double Now() const { return At(Clock::now()); }
  double At(Clock::time_point wall) const;
  // The wall time when the clock reads `t`; `wall` (now) when it reads more already.
  Clock::time_point WallAt(double t, Clock::time_point wall) const;
  double time_scale() const { return scale_; }

 private:
  const double scale_;
  const Clock::time_point start_;
  double base_ = 0.0;  // dispatcher seconds at start_
};

// `seconds` of wall time as a steady-clock duration.
DispatchClock::Clock::duration WallDuration(double seconds);

}  // namespace dispatch::server
