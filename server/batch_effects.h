// BatchEffects: what one batch of the dispatcher loop owes the outside world, and when it may
// go out (dispatcher.h, read-your-writes). Replies, Welcomes and stream ends are deferred to
// the end of the batch and need the snapshot that holds the batch's changes published first;
// robot plans, grants and holds are deferred too but need no snapshot. Journal events
// (WatchOrders) need the snapshot too but do not hasten it: they go out, in order, after the
// next publish (a streaming fleet finishing orders would otherwise force a snapshot for
// nearly every batch). A
// change nobody is told about yet (a robot report, a grant) is published at most every
// kPublishEvery, or every kPublishShare times the last publish's time if that is longer: a
// snapshot copies every robot and order, 500 robots reporting at 10 Hz make hundreds of
// batches a second, and with a thousand robots a snapshot takes milliseconds of the loop that
// grants and holds wait for (this keeps such publishes to about a tenth of the loop's time).
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
  static constexpr int kPublishShare = 10;

  // The loop's state changed since the last snapshot.
  void MarkChanged() { changed_ = true; }
  bool changed() const { return changed_; }
  // Runs `effect` at the end of the batch; with `after_publish` only after the snapshot.
  void Defer(std::function<void()> effect, bool after_publish);
  // Runs `effect` after the next publish, in order with the other announcements, without
  // making that publish come sooner than period() after the last one.
  void Announce(std::function<void()> effect);
  // The snapshot is to be published now: the state changed, and a deferred effect waits for it
  // or the last snapshot is period() old.
  bool PublishDue(Clock::time_point now) const;
  // `took`: how long the publish took (the snapshot's build).
  void Published(Clock::time_point now, Clock::duration took = {});
  // The least time between publishes nobody waits for (see above).
  Clock::duration period() const { return period_; }
  // When the loop must wake at the latest: at `next_tick`, or earlier to publish a change.
  Clock::time_point WakeBy(Clock::time_point next_tick) const;
  // Runs the effects deferred so far, in order, then the announcements made before the last
  // publish (an effect that defers or announces another leaves it for the next call).
  void RunDeferred();

 private:
  bool changed_ = true;  // nothing is published yet
  Clock::time_point last_publish_{};
  Clock::duration period_ = kPublishEvery;
  std::vector<std::function<void()>> deferred_;
  std::vector<std::function<void()>> announced_;  // waiting for the next publish
  std::vector<std::function<void()>> released_;   // published: out at the next RunDeferred
  bool need_publish_ = false;  // one of deferred_ waits for the snapshot
};

}  // namespace dispatch::server
