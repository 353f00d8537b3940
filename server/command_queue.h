// CommandQueue: the dispatcher loop's inbox (SPEC §4 "Concurrency"). API threads and the
// workers post commands; the loop takes everything queued at once, as one batch, waiting until
// something is posted, the queue is stopped, or the time it must wake anyway. After Stop the
// queue still takes commands, and the loop runs them until it finds the queue empty.
//
// Thread-safe: mu_ guards every member.
#pragma once

#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>

namespace dispatch::server {

class CommandQueue {
 public:
  using Clock = std::chrono::steady_clock;
  using Command = std::function<void()>;
  struct Batch {
    std::deque<Command> commands;  // in the order they were posted
    bool stopping = false;         // Stop had been called when the batch was taken
  };

  void Post(Command command);
  // Every command queued, once there is one, the queue is stopped or `wake` has come.
  Batch Take(Clock::time_point wake);
  // Wakes the loop; from now on every batch says stopping.
  void Stop();
  bool stopping() const;
  bool empty() const;

 private:
  mutable std::mutex mu_;
  std::condition_variable cv_;
  std::deque<Command> commands_;
  bool stopping_ = false;
};

}  // namespace dispatch::server
