// WorkerThread: one background thread that runs jobs in FIFO order, so the dispatcher loop
// (SPEC §4 "Concurrency": the one writer) never stalls on work that only reads: a new order's
// route searches (on a large floor the lazy route table runs a reverse Dijkstra over the whole
// floor towards every new pick or drop: milliseconds each) and the allocation rounds (the
// auction over every robot). A job hands its result back by posting to the loop.
//
// A job gets `cancelled` = true when the worker is stopping: it skips its work but still runs
// its hand-over (nothing handed to the worker is dropped). Stop() runs the jobs still queued
// that way and joins; Run() after Stop() runs the job at once on the caller's thread,
// cancelled. Thread-safe.
//
// `nice` > 0 runs the thread at that much lower CPU priority (Linux: setpriority on the
// thread), so that on a busy machine the loop and the robot streams get the cores first.
#pragma once

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>

namespace dispatch::server {

class WorkerThread {
 public:
  using Job = std::function<void(bool cancelled)>;
  explicit WorkerThread(int nice = 0);
  ~WorkerThread();  // Stop()
  WorkerThread(const WorkerThread&) = delete;
  WorkerThread& operator=(const WorkerThread&) = delete;

  void Run(Job job);
  void Stop();

 private:
  void Loop();

  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<Job> jobs_;   // guarded by mu_
  bool stopping_ = false;  // guarded by mu_
  std::thread thread_;
};

}  // namespace dispatch::server
