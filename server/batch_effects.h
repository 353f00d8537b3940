// BatchEffects: what one batch of the dispatcher loop owes the outside world, and when it may
// go out (dispatcher.h, read-your-writes). Replies, journal events, Welcomes and stream ends
// are deferred to the end of the batch and need the snapshot that holds the batch's changes
// published first; robot plans, grants and holds are deferred too but need no snapshot. A
// change nobody is told about yet (a robot report, a grant) is published at most every
// kPublishEvery: a snapshot copies every robot and order, and 500 robots reporting at 10 Hz
// make hundreds of batches a second.
//
// Not thread-safe: the dispatcher's loop owns it.
#pragma once

#include <chrono>
#include <functional>
#include <vector>

namespace dispatch::server {

class BatchEffects {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr std::chrono::milliseconds kPublishEvery{20};

  // The loop's state changed since the last snapshot.
  void MarkChanged() { changed_ = true; }
  bool changed() const { return changed_; }
  // Runs `effect` at the end of the batch; with `after_publish` only after the snapshot.
  void Defer(std::function<void()> effect, bool after_publish);
  // The snapshot is to be published now: the state changed, and a deferred effect waits for it
  // or the last snapshot is kPublishEvery old.
  bool PublishDue(Clock::time_point now) const;
  void Published(Clock::time_point now);
  // When the loop must wake at the latest: at `next_tick`, or earlier to publish a change.
  Clock::time_point WakeBy(Clock::time_point next_tick) const;
  // Runs the effects deferred so far, in order (an effect that defers another leaves it for
  // the next call).
  void RunDeferred();

 private:
  bool changed_ = true;  // nothing is published yet
  Clock::time_point last_publish_{};
  std::vector<std::function<void()>> deferred_;
  bool need_publish_ = false;  // one of deferred_ waits for the snapshot
};

}  // namespace dispatch::server
