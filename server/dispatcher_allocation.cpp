// Dispatcher: allocation rounds (see dispatcher.h, "Allocation"). The core makes a round's
// inputs (AllocatePending); the round worker runs the strategy on them (round_worker.h); the
// loop commits the awards that still hold, a few per loop turn (CommitNext). When rounds run
// is RoundSchedule's (round_schedule.h).
#include "server/dispatcher.h"

namespace dispatch::server {
namespace {

// Awards stored per loop turn: a large round (a hundred orders, each explanation with the bids
// of every robot) would otherwise hold the loop for a quarter second.
constexpr std::size_t kCommitChunk = 4;

}  // namespace

void Dispatcher::AllocatePending() {
  if (!rounds_due_.Begin()) return;  // after the running round is committed
  engine::RoundCommit keys;
  const double now = Now();
  std::optional<engine::RoundInput> made = core_->MakeRound(now, keys);
  if (!made) return;
  rounds_due_.Started(now);
  round_worker_.Run(std::move(*made), std::move(keys), [this](std::shared_ptr<ServerRound> round, bool cancelled) {
    Post([this, round, cancelled] {
      core_->RoundResult(round->commit, cancelled);
      CommitNext(round);
    });
  });
}

void Dispatcher::CommitNext(std::shared_ptr<ServerRound> round) {
  engine::RoundCommit& commit = round->commit;
  const engine::Change change = core_->PlanAwards(commit, kCommitChunk, Now());
  if (commit.again) rounds_due_.Again();
  if (!Commit(change, round.get())) {
    rounds_due_.Retry();  // the store failed: the rest stays accepted, tried on the next tick
  } else {
    core_->Committed(commit, change);
    if (commit.next < commit.awards.size()) {
      Post([this, round] { CommitNext(round); });
      return;
    }
  }
  rounds_due_.Finished();
}

}  // namespace dispatch::server
