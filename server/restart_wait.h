// RestartWait: after a restart, traffic control releases nothing until every robot that was on
// line when the old process stopped has reported again (it may have driven on since its record
// was written, and may still be driving to the horizon the old process released), or until a
// deadline (the heartbeat timeout after the loop started) has passed. See dispatcher.h,
// "Restart". Not thread-safe: the dispatcher's loop owns it.
#pragma once

#include <chrono>
#include <set>
#include <string>

namespace dispatch::server {

class RestartWait {
 public:
  using Clock = std::chrono::steady_clock;

  void Await(const std::string& robot_id) { awaited_.insert(robot_id); }
  void SetDeadline(Clock::time_point deadline) { deadline_ = deadline; }
  bool waiting() const { return !awaited_.empty(); }
  bool Expired(Clock::time_point now) const { return waiting() && now >= deadline_; }
  // The robot reported: true when that was the last one awaited (the wait is over).
  bool Reported(const std::string& robot_id) { return awaited_.erase(robot_id) > 0 && awaited_.empty(); }
  void End() { awaited_.clear(); }
  const std::set<std::string>& awaited() const { return awaited_; }
  std::string List() const;  // "R3, R7"

 private:
  std::set<std::string> awaited_;
  Clock::time_point deadline_{};
};

}  // namespace dispatch::server
