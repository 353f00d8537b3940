// RoundWorker: runs the dispatcher's allocation rounds off its loop (dispatcher.h,
// "Allocation"): the strategy (engine::RoundRunner) on a worker thread of its own, at a lower
// CPU priority than the loop, so traffic control never waits for an auction.
//
// A round comes back as a ServerRound: the core's commit (engine::RoundCommit, with the keys
// the core's MakeRound gave) and, per award, its explanation as the order views keep it
// (AllocationRecord, the best bids only: explanation.h) and as the journal stores it
// (AllocationDetail). The loop then only stores and applies it, a few awards at a time.
//
// Thread safety: Run and Stop from one thread (the loop; Stop also from the owner's
// destructor). `done` runs on the worker, or - for a round still queued at Stop, or one run
// after it - on the stopping or calling thread with `cancelled` and no awards: nothing handed
// to the worker is dropped. The RoundRunner is the worker's only.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "engine/dispatch/allocation_round.h"
#include "engine/dispatch/dispatch_core.h"
#include "server/snapshot.h"
#include "server/worker_thread.h"

namespace dispatch::server {

struct ServerRound {
  engine::RoundCommit commit;
  std::vector<AllocationRecord> records;
  std::vector<std::string> details;  // AllocationDetail(records[i])
};

// The round of `result`, run at dispatcher time `now` with `config`'s weights: commit.awards
// are result's awards without their bids (the core needs the winners and the reason only);
// commit.keys and origin are left to the caller.
ServerRound RecordRound(engine::RoundResult result, const engine::AllocationConfig& config, double now);

class RoundWorker {
 public:
  using Done = std::function<void(std::shared_ptr<ServerRound> round, bool cancelled)>;

  RoundWorker(std::unique_ptr<engine::RoundRunner> runner, engine::AllocationConfig config, int nice);

  // Runs the round of `input`; `keys` is what the core's MakeRound filled in for it.
  void Run(engine::RoundInput input, engine::RoundCommit keys, Done done);
  void Stop() { worker_.Stop(); }

 private:
  std::unique_ptr<engine::RoundRunner> runner_;
  const engine::AllocationConfig config_;
  WorkerThread worker_;  // last: stopped (its rounds handed back) before the rest goes
};

}  // namespace dispatch::server
