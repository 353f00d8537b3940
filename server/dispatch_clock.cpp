#include "server/dispatch_clock.h"

namespace dispatch::server {

double DispatchClock::At(Clock::time_point wall) const {
  const std::chrono::duration<double> elapsed = wall - start_;
  return base_ + elapsed.count() * scale_;
}

DispatchClock::Clock::time_point DispatchClock::WallAt(double t, Clock::time_point wall) const {
  return wall + WallDuration(std::max(0.0, t - At(wall)) / scale_);
}

DispatchClock::Clock::duration WallDuration(double seconds) {
  return std::chrono::duration_cast<DispatchClock::Clock::duration>(std::chrono::duration<double>(seconds));
}

}  // namespace dispatch::server
