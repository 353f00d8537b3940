#include "server/worker_thread.h"

#include <sys/resource.h>
#include <unistd.h>

#include <utility>

namespace dispatch::server {

WorkerThread::WorkerThread(int nice)
    : thread_([this, nice] {
        // Best effort: without the permission to change it the thread runs at normal priority.
        if (nice > 0) (void)::setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), nice);
        Loop();
      }) {}

WorkerThread::~WorkerThread() { Stop(); }

void WorkerThread::Run(Job job) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (!stopping_) {
      jobs_.push_back(std::move(job));
      cv_.notify_one();
      return;
    }
  }
  job(true);
}

void WorkerThread::Stop() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stopping_ = true;
  }
  cv_.notify_one();
  if (thread_.joinable()) thread_.join();
}

void WorkerThread::Loop() {
  for (;;) {
    Job job;
    bool cancelled = false;
    {
      std::unique_lock<std::mutex> lock(mu_);
      cv_.wait(lock, [&] { return !jobs_.empty() || stopping_; });
      if (jobs_.empty()) return;  // stopping, nothing left
      job = std::move(jobs_.front());
      jobs_.pop_front();
      cancelled = stopping_;
    }
    job(cancelled);
  }
}

}  // namespace dispatch::server
