#include "server/command_queue.h"

#include <utility>

namespace dispatch::server {

void CommandQueue::Post(Command command) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    commands_.push_back(std::move(command));
  }
  cv_.notify_one();
}

CommandQueue::Batch CommandQueue::Take(Clock::time_point wake) {
  Batch batch;
  std::unique_lock<std::mutex> lock(mu_);
  cv_.wait_until(lock, wake, [&] { return !commands_.empty() || stopping_; });
  batch.commands.swap(commands_);
  batch.stopping = stopping_;
  return batch;
}

void CommandQueue::Stop() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stopping_ = true;
  }
  cv_.notify_all();
}

bool CommandQueue::stopping() const {
  std::lock_guard<std::mutex> lock(mu_);
  return stopping_;
}

bool CommandQueue::empty() const {
  std::lock_guard<std::mutex> lock(mu_);
  return commands_.empty();
}

}  // namespace dispatch::server
