#include "server/round_worker.h"

#include <spdlog/spdlog.h>

#include <utility>

#include "server/explanation.h"
#include "server/json_convert.h"

namespace dispatch::server {

ServerRound RecordRound(engine::RoundResult result, const engine::AllocationConfig& config, double now) {
  ServerRound round;
  for (engine::RoundAward& award : result.awards) {
    AllocationRecord record{award.award, config.alpha, config.beta, config.zeta, now};
    KeepBestBids(record);
    round.details.push_back(AllocationDetail(record));
    round.records.push_back(std::move(record));
    award.award.bids.clear();
    award.award.companion_bids.clear();
    round.commit.awards.push_back(std::move(award));
  }
  return round;
}

RoundWorker::RoundWorker(std::unique_ptr<engine::RoundRunner> runner, engine::AllocationConfig config, int nice)
    : runner_(std::move(runner)), config_(std::move(config)), worker_(nice) {}

void RoundWorker::Run(engine::RoundInput input, engine::RoundCommit keys, Done done) {
  auto shared_input = std::make_shared<const engine::RoundInput>(std::move(input));
  auto shared_keys = std::make_shared<engine::RoundCommit>(std::move(keys));
  worker_.Run([this, shared_input, shared_keys, done = std::move(done)](bool cancelled) {
    auto round = std::make_shared<ServerRound>();
    if (!cancelled) {
      engine::RoundResult result = runner_->Run(*shared_input);
      for (const std::string& note : result.notes) spdlog::warn("{}", note);
      *round = RecordRound(std::move(result), config_, shared_input->now);
    }
    round->commit.keys = std::move(shared_keys->keys);
    round->commit.origin = shared_keys->origin;
    done(std::move(round), cancelled);
  });
}

}  // namespace dispatch::server
