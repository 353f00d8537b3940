// DistanceWatch: the closest two robots (of different agents) seen so far, as the snapshot
// and /metrics show it (dispatch_min_robot_distance_meters). The gate measures it from the
// robots' reported positions when sampled (engine::TrafficGate::SampleDistances, O(robots));
// the dispatcher samples at most every kSampleEvery (robots report at about 10 Hz) and keeps
// the last closest approach it saw, to tell when it changed.
//
// Not thread-safe: the dispatcher's loop owns it.
#pragma once

#include <chrono>

#include "engine/traffic/traffic_gate.h"

namespace dispatch::server {

class DistanceWatch {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr std::chrono::milliseconds kSampleEvery{50};  // 20 Hz

  // True when a sample is due at `wall`; the next one is then due kSampleEvery later.
  bool SampleDue(Clock::time_point wall);
  // Takes the gate's closest approach: true when it differs from the last one taken.
  bool Update(const engine::MinDistance& closest);
  const engine::MinDistance& closest() const { return closest_; }

 private:
  engine::MinDistance closest_;
  Clock::time_point next_sample_{};
};

}  // namespace dispatch::server
