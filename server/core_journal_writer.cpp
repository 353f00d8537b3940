#include "server/core_journal_writer.h"

#include <spdlog/spdlog.h>

#include <iterator>
#include <utility>
#include <vector>

namespace dispatch::server {

CoreJournalWriter::CoreJournalWriter(storage::JournalStore& journal, std::int64_t run, std::uint64_t max_bytes,
                                     int nice)
    : journal_(journal), run_(run), max_bytes_(max_bytes), worker_(nice) {}

void CoreJournalWriter::Write(engine::JournaledCore& core) {
  if (stopped_) return;
  std::vector<engine::JournalEntry> entries = core.TakeEntries();
  if (pending_.empty()) {
    pending_ = std::move(entries);
  } else {
    pending_.insert(pending_.end(), std::make_move_iterator(entries.begin()), std::make_move_iterator(entries.end()));
  }
  const bool full = full_.load();
  if (full) {
    core.StopRecording();
    stopped_ = true;
    return HandOver(true);
  }
  if (pending_.empty()) return;
  const auto now = std::chrono::steady_clock::now();
  if (pending_.size() < kMaxPending && (writing_.load() > 0 || now - last_hand_over_ < kWriteEvery)) return;
  last_hand_over_ = now;
  HandOver(false);
}

void CoreJournalWriter::Stop() {
  if (!stopped_ && !pending_.empty()) HandOver(false);
  worker_.Stop();
}

void CoreJournalWriter::HandOver(bool full) {
  ++writing_;
  worker_.Run([this, full, entries = std::move(pending_)](bool) {
    // Written even when the worker stops (cancelled): the journal must hold the run's end.
    // After a failed write nothing more is (a gap would make the rest unreplayable); the run
    // is marked truncated.
    auto written = failed_ ? journal_.Append(run_, {}, true) : journal_.Append(run_, entries, full);
    --writing_;
    if (failed_) return;
    if (!written.ok()) {
      spdlog::error("journal run {}: {} entries not written, recording stops (a replay ends before them): {}", run_,
                    entries.size(), written.error().message);
      failed_ = true;
      full_ = true;
      return;
    }
    bytes_ += *written;
    if (max_bytes_ > 0 && bytes_ >= max_bytes_ && !full_.exchange(true)) {
      spdlog::warn("journal run {} reached its limit of {} MB: recording stops (a replay covers the run so far)", run_,
                   max_bytes_ >> 20);
    }
  });
  pending_.clear();  // moved from
}

}  // namespace dispatch::server
