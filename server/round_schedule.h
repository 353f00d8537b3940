// RoundSchedule: when the dispatcher runs an allocation round (dispatcher.h, "Allocation").
// A round is due when the core says so after a batch, when an award of the running round did
// not hold, or on the tick after a store failure left work undone. At most one round is on
// its way at a time (on the worker, or being committed a few awards per loop turn); one that
// becomes due meanwhile runs once it is committed. With a batch window, a round starts no
// sooner than the window after the previous one started: a due round waits (Waiting), and
// the orders arriving meanwhile join it.
//
// Not thread-safe: the dispatcher's loop owns it.
#pragma once

namespace dispatch::server {

class RoundSchedule {
 public:
  // Dispatcher seconds between two round starts at least (>= 0; 0: none).
  void SetWindow(double seconds) { window_ = seconds; }
  // A round is to run at the end of this batch.
  void MarkDue() { due_ = true; }
  bool due() const { return due_; }
  // A due round waits for the window until not_before().
  bool Waiting(double now) const { return due_ && now < not_before_; }
  double not_before() const { return not_before_; }
  // The loop is about to make a round: true when it may; false when one is still on its way
  // (the new one then runs after it).
  bool Begin() {
    due_ = false;
    if (running_) {
      again_ = true;
      return false;
    }
    retry_ = false;
    return true;
  }
  // The round Begin allowed is on its way (the core had something to allocate) at `now`.
  void Started(double now) {
    running_ = true;
    not_before_ = now + window_;
  }
  // An award of the running round did not hold: another round once it is committed.
  void Again() { again_ = true; }
  // A store write failed: the work it left is tried on the next tick.
  void Retry() { retry_ = true; }
  // The running round is committed (or given up after a store failure).
  void Finished() {
    running_ = false;
    if (again_) {
      again_ = false;
      due_ = true;
    }
  }
  // The loop's tick: a round is due when a store failure left work.
  void Tick() {
    if (retry_) due_ = true;
  }
  bool running() const { return running_; }

 private:
  bool due_ = false;      // a round runs at the end of this batch
  bool running_ = false;  // a round is on the worker or waits to be committed
  bool again_ = false;    // a round became due meanwhile
  bool retry_ = false;    // a store failure left work for the next tick
  double window_ = 0.0;
  double not_before_ = 0.0;  // dispatcher time the next round may start
};

}  // namespace dispatch::server
