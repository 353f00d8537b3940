// CoreJournalWriter: writes the dispatch core's journal of one run (issue 15 §4) into the
// journal store, off the dispatcher's loop. Each call of Write hands the entries the loop's
// JournaledCore collected since the last call to a worker thread of its own, which appends
// them in order, one transaction per call. Recording stops for good once `max_bytes` of
// entries are written (0: no limit) or a write failed; the run is then marked truncated (a
// replay covers it up to there, never with a gap).
//
// Write is called from the loop thread only; Stop (idempotent) writes what is queued and joins.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>

#include "engine/dispatch/journaled_core.h"
#include "server/worker_thread.h"
#include "storage/journal_store.h"

namespace dispatch::server {

class CoreJournalWriter {
 public:
  CoreJournalWriter(storage::JournalStore& journal, std::int64_t run, std::uint64_t max_bytes, int nice);
  ~CoreJournalWriter() { Stop(); }

  void Write(engine::JournaledCore& core);
  void Stop() { worker_.Stop(); }

 private:
  storage::JournalStore& journal_;
  const std::int64_t run_;
  const std::uint64_t max_bytes_;
  WorkerThread worker_;
  std::uint64_t bytes_ = 0;      // worker only
  bool failed_ = false;          // worker only: a write failed
  std::atomic<bool> full_{false};  // set by the worker at max_bytes or a failure
  bool stopped_ = false;         // loop: recording stopped, marker written
};

}  // namespace dispatch::server
