#include "server/distance_watch.h"

namespace dispatch::server {

bool DistanceWatch::SampleDue(Clock::time_point wall) {
  if (wall < next_sample_) return false;
  next_sample_ = wall + kSampleEvery;
  return true;
}

bool DistanceWatch::Update(const engine::MinDistance& closest) {
  if (closest.distance == closest_.distance && closest.time == closest_.time) return false;
  closest_ = closest;
  return true;
}

}  // namespace dispatch::server
