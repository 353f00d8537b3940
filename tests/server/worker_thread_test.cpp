#include "server/worker_thread.h"

#include <gtest/gtest.h>

#include <future>
#include <mutex>
#include <vector>

namespace dispatch::server {
namespace {

// A job log shared by the jobs (they run on the worker, Stop's caller or Run's caller).
struct Log {
  std::mutex mu;
  std::vector<std::pair<int, bool>> entries;  // (job, cancelled)
  void Add(int job, bool cancelled) {
    std::lock_guard<std::mutex> lock(mu);
    entries.emplace_back(job, cancelled);
  }
};

TEST(WorkerThreadTest, RunsJobsInOrderAndHandsOverQueuedOnesWhenStopped) {
  Log log;
  std::promise<void> started, release;
  auto released = release.get_future().share();
  WorkerThread worker;
  worker.Run([&](bool cancelled) {
    log.Add(0, cancelled);
    started.set_value();
    released.wait();  // holds the worker: the next jobs queue up behind it
  });
  started.get_future().wait();
  for (int i = 1; i <= 3; ++i) worker.Run([&log, i](bool cancelled) { log.Add(i, cancelled); });
  std::thread stopper([&] { worker.Stop(); });
  release.set_value();
  stopper.join();
  worker.Run([&log](bool cancelled) { log.Add(4, cancelled); });  // after Stop: at once
  ASSERT_EQ(log.entries.size(), 5u);
  for (int i = 0; i <= 4; ++i) EXPECT_EQ(log.entries[static_cast<std::size_t>(i)].first, i);
  EXPECT_FALSE(log.entries[0].second);
  EXPECT_TRUE(log.entries[4].second);
}

TEST(WorkerThreadTest, JobsRunOffTheCallersThreadUntilStopped) {
  WorkerThread worker;
  std::promise<std::pair<std::thread::id, bool>> seen;
  worker.Run([&](bool cancelled) { seen.set_value({std::this_thread::get_id(), cancelled}); });
  const auto [id, cancelled] = seen.get_future().get();
  EXPECT_NE(id, std::this_thread::get_id());
  EXPECT_FALSE(cancelled);
  worker.Stop();
  worker.Stop();  // idempotent
  std::thread::id inline_id;
  worker.Run([&](bool c) {
    inline_id = std::this_thread::get_id();
    EXPECT_TRUE(c);
  });
  EXPECT_EQ(inline_id, std::this_thread::get_id());
}

}  // namespace
}  // namespace dispatch::server
