// RoundSchedule: when the dispatcher runs an allocation round (dispatcher.h, "Allocation").
// A round is due when the core says so after a batch, when an award of the running round did
// not hold, or on the tick after a store failure left work undone. At most one round is on
// its way at a time (on the worker, or being committed a few awards per loop turn); one that
// becomes due meanwhile runs once it is committed.
//
// Not thread-safe: the dispatcher's loop owns it.
#pragma once

namespace dispatch::server {

class RoundSchedule {
 public:
  // A round is to run at the end of this batch.
  void MarkDue() { due_ = true; }
  bool due() const { return due_; }
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
  // The round Begin allowed is on its way (the core had something to allocate).
  void Started() { running_ = true; }
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
};

}  // namespace dispatch::server
