// Dispatcher: the core's journal (see dispatcher.h, DispatcherOptions::journal). The loop
// takes the batch's entries from the JournaledCore and the journal worker writes them, in
// order, one transaction per batch; a failed write is logged and the run marked incomplete.
#include <spdlog/spdlog.h>

#include "server/dispatcher.h"

namespace dispatch::server {

void Dispatcher::WriteJournal() {
  storage::JournalStore* journal = options_.journal;
  if (!journal || journal_stopped_) return;
  std::vector<engine::JournalEntry> entries = core_->TakeEntries();
  const bool full = journal_full_.load();
  if (full) {
    core_->StopRecording();
    journal_stopped_ = true;
  }
  if (entries.empty() && !full) return;
  const std::int64_t run = options_.journal_run;
  const std::uint64_t limit = options_.journal_max_bytes;
  journal_worker_->Run([this, journal, run, limit, full, entries = std::move(entries)](bool) {
    // Written even when the worker stops (cancelled): the journal must hold the run's end.
    // After a failed write nothing more is (a gap would make the rest unreplayable); the run
    // is marked truncated.
    auto written = journal_failed_ ? journal->Append(run, {}, true) : journal->Append(run, entries, full);
    if (journal_failed_) return;
    if (!written.ok()) {
      spdlog::error("journal run {}: {} entries not written, recording stops (a replay ends before them): {}", run,
                    entries.size(), written.error().message);
      journal_failed_ = true;
      journal_full_ = true;
      return;
    }
    journal_bytes_ += *written;
    if (limit > 0 && journal_bytes_ >= limit && !journal_full_.exchange(true)) {
      spdlog::warn("journal run {} reached its limit of {} MB: recording stops (a replay covers the run so far)", run,
                   limit >> 20);
    }
  });
}

}  // namespace dispatch::server
