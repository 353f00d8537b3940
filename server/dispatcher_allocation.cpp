// Dispatcher: allocation rounds (see dispatcher.h, "Allocation"). The core makes a round's
// inputs (AllocatePending); the allocation worker runs the strategy on them (RunRound); the
// loop commits the awards that still hold, a few per loop turn (CommitNext).
#include <spdlog/spdlog.h>

#include "server/dispatcher.h"
#include "server/explanation.h"
#include "server/json_convert.h"

namespace dispatch::server {
namespace {

// Awards stored per loop turn: a large round (a hundred orders, each explanation with the bids
// of every robot) would otherwise hold the loop for a quarter second.
constexpr std::size_t kCommitChunk = 4;

}  // namespace

void Dispatcher::AllocatePending() {
  allocation_due_ = false;
  if (round_running_) {
    round_again_ = true;  // after the running round is committed
    return;
  }
  retry_allocation_ = false;
  auto keys = std::make_shared<engine::RoundCommit>();
  std::optional<engine::RoundInput> made = core_->MakeRound(Now(), *keys);
  if (!made) return;
  auto input = std::make_shared<const engine::RoundInput>(std::move(*made));
  round_running_ = true;
  allocation_worker_->Run([this, input, keys](bool cancelled) {
    auto round = cancelled ? std::make_shared<ServerRound>() : RunRound(*input);
    round->commit.keys = std::move(keys->keys);
    round->commit.origin = keys->origin;
    Post([this, round, cancelled] {
      core_->RoundResult(round->commit, cancelled);
      CommitNext(round);
    });
  });
}

std::shared_ptr<Dispatcher::ServerRound> Dispatcher::RunRound(const engine::RoundInput& input) {
  engine::RoundResult result = rounds_->Run(input);
  for (const std::string& note : result.notes) spdlog::warn("{}", note);
  auto round = std::make_shared<ServerRound>();
  for (engine::RoundAward& award : result.awards) {
    AllocationRecord record{award.award, options_.allocation.alpha, options_.allocation.beta,
                            options_.allocation.zeta, input.now};
    KeepBestBids(record);
    round->details.push_back(AllocationDetail(record));
    round->records.push_back(std::move(record));
    award.award.bids.clear();  // the core needs the winners and the reason only
    award.award.companion_bids.clear();
    round->commit.awards.push_back(std::move(award));
  }
  return round;
}

void Dispatcher::CommitNext(std::shared_ptr<ServerRound> round) {
  engine::RoundCommit& commit = round->commit;
  const engine::Change change = core_->PlanAwards(commit, kCommitChunk, Now());
  if (commit.again) round_again_ = true;
  if (!Commit(change, round.get())) {
    retry_allocation_ = true;  // the store failed: the rest stays accepted, tried on the next tick
  } else {
    core_->Committed(commit, change);
    if (commit.next < commit.awards.size()) {
      Post([this, round] { CommitNext(round); });
      return;
    }
  }
  round_running_ = false;
  if (round_again_) {
    round_again_ = false;
    allocation_due_ = true;
  }
}

}  // namespace dispatch::server
