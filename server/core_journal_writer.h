// CoreJournalWriter: writes the dispatch core's journal of one run (issue 15 §4) into the
// journal store, off the dispatcher's loop. Each call of Write takes the entries the loop's
// JournaledCore collected since the last call; they go to a worker thread of its own, which
// appends them in order, one transaction per hand-over. A hand-over waits until the last one
// is written and kWriteEvery has passed since it (or kMaxPending entries wait): the loop calls
// Write after every batch, hundreds of times a second with a large fleet, and a transaction
// per batch cost more than the entries. Recording stops for good once `max_bytes` of entries
// are written (0: no limit) or a write failed; the run is then marked truncated (a replay
// covers it up to there, never with a gap).
//
// Write is called from the loop thread only; Stop (idempotent) hands over and writes what
// waits, and joins.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <vector>

#include "engine/dispatch/journaled_core.h"
#include "server/worker_thread.h"
#include "storage/journal_store.h"

namespace dispatch::server {

class CoreJournalWriter {
 public:
  CoreJournalWriter(storage::JournalStore& journal, std::int64_t run, std::uint64_t max_bytes, int nice);
  ~CoreJournalWriter() { Stop(); }

  static constexpr std::chrono::milliseconds kWriteEvery{20};
  static constexpr std::size_t kMaxPending = 8192;

  void Write(engine::JournaledCore& core);
  void Stop();

 private:
  void HandOver(bool full);

  storage::JournalStore& journal_;
  const std::int64_t run_;
  const std::uint64_t max_bytes_;
  WorkerThread worker_;
  std::uint64_t bytes_ = 0;      // worker only
  bool failed_ = false;          // worker only: a write failed
  std::atomic<bool> full_{false};  // set by the worker at max_bytes or a failure
  bool stopped_ = false;         // loop: recording stopped, marker written
  std::vector<engine::JournalEntry> pending_;              // loop: not handed over yet
  std::atomic<int> writing_{0};                            // hand-overs not written yet
  std::chrono::steady_clock::time_point last_hand_over_{};  // loop
};

}  // namespace dispatch::server
