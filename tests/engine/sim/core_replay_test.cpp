// CoreReplay (engine/dispatch/core_replay.h) on journals of SimulateOnCore runs: a run on the
// dispatch core replays entry by entry with the same outputs and the same order outcomes; a
// changed entry is where the replay diverges; entries that refer to nothing are errors.
#include "engine/dispatch/core_replay.h"

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "engine/cli/scenario.h"
#include "engine/sim/core_stream.h"
#include "tests/engine/sim/stream_test_support.h"

namespace dispatch::engine::testing {
namespace {

StreamConfig Config() {
  StreamConfig c;
  c.max_time = 3000;
  return c;
}

ReplaySetup SetupOf(const World& w, const StreamConfig& c) {
  ReplaySetup s;
  s.map = w.map;
  s.routes = w.routes;
  s.core = CoreOptionsOf(c);
  s.strategy = AllocationStrategyName(c.strategy);
  s.allocation = c.allocation;
  return s;
}

struct Recorded {
  StreamResult result;
  std::vector<JournalEntry> journal;
};

Recorded Record(const World& w, const Stream& stream, const StreamConfig& c) {
  Recorded r;
  auto run = SimulateOnCore(w.map, w.routes, stream.robots, stream.orders, c, &r.journal);
  if (!run.ok()) throw std::runtime_error(run.error().message);
  r.result = std::move(run).value();
  return r;
}

// The first entry whose replayed output differs (0: none), and the replay.
std::pair<std::uint64_t, std::unique_ptr<CoreReplay>> Replay(const World& w, const StreamConfig& c,
                                                             const std::vector<JournalEntry>& journal) {
  auto replay = CoreReplay::Create(SetupOf(w, c));
  if (!replay.ok()) throw std::runtime_error(replay.error().message);
  for (const JournalEntry& e : journal) {
    auto out = (*replay)->Feed(e);
    if (!out.ok()) throw std::runtime_error(out.error().message);
    if (*out != e.output) return {e.seq, std::move(replay).value()};
  }
  return {0, std::move(replay).value()};
}

TEST(CoreReplayTest, ARunWithFormationsReplaysEntryByEntry) {
  const World w = Chu();
  const StreamConfig c = Config();
  const Stream stream = ChuStream(w, 40, 3, 0.2);
  const Recorded rec = Record(w, stream, c);
  ASSERT_GT(rec.journal.size(), 1000u);
  // Journaling changes nothing of the run.
  auto plain = SimulateOnCore(w.map, w.routes, stream.robots, stream.orders, c);
  ASSERT_TRUE(plain.ok());
  EXPECT_EQ(plain->completed, rec.result.completed);
  EXPECT_EQ(plain->makespan, rec.result.makespan);
  EXPECT_EQ(plain->steps, rec.result.steps);
  std::map<CoreInput::Kind, std::size_t> kinds;
  for (std::size_t i = 0; i < rec.journal.size(); ++i) {
    ASSERT_EQ(rec.journal[i].seq, i + 1) << "entries are numbered without gaps";
    ++kinds[rec.journal[i].input.kind];
  }
  for (auto k : {CoreInput::Kind::kConnect, CoreInput::Kind::kAddOrder, CoreInput::Kind::kMakeRound,
                 CoreInput::Kind::kRoundResult, CoreInput::Kind::kPlanAwards, CoreInput::Kind::kApply,
                 CoreInput::Kind::kReport, CoreInput::Kind::kReached, CoreInput::Kind::kPlanTask,
                 CoreInput::Kind::kStep}) {
    EXPECT_GT(kinds[k], 0u) << CoreInputKindName(k);
  }
  auto [diverged, replay] = Replay(w, c, rec.journal);
  EXPECT_EQ(diverged, 0u);
  // The order outcomes the replay traced are the run's.
  std::map<std::string, bool> completed;
  for (const StreamOrderOutcome& o : rec.result.orders) completed[o.order_id] = o.completed;
  std::size_t traced_completed = 0;
  for (const OrderTrace& t : replay->orders()) {
    ASSERT_TRUE(completed.count(t.id)) << t.id;
    EXPECT_EQ(t.state == OrderState::kCompleted, completed[t.id]) << t.id << " " << OrderStateName(t.state);
    traced_completed += t.state == OrderState::kCompleted ? 1 : 0;
  }
  EXPECT_EQ(traced_completed, rec.result.completed);
  EXPECT_GT(rec.result.completed, 0u);
  EXPECT_GT(replay->core().counts().grants, 0u);
}

TEST(CoreReplayTest, AChangedEntryIsWhereTheReplayDiverges) {
  const World w = Chu();
  StreamConfig c = Config();
  c.max_time = 600;
  const Stream stream = ChuStream(w, 10, 5);
  Recorded rec = Record(w, stream, c);
  // The first round's commit, told to commit nothing: its recorded awards are not replayed.
  std::uint64_t target = 0;
  for (JournalEntry& e : rec.journal) {
    if (e.input.kind == CoreInput::Kind::kPlanAwards && !e.output.empty()) {
      e.input.max = 0;
      target = e.seq;
      break;
    }
  }
  ASSERT_NE(target, 0u);
  EXPECT_EQ(Replay(w, c, rec.journal).first, target);
  // Another strategy than the recorded one decides other awards: the first round result differs.
  StreamConfig greedy = c;
  greedy.strategy = AllocationStrategy::kGreedy;
  Recorded auction = Record(w, stream, c);
  const auto [at, replay] = Replay(w, greedy, auction.journal);
  ASSERT_NE(at, 0u);
  EXPECT_EQ(auction.journal[at - 1].input.kind, CoreInput::Kind::kRoundResult);
}

TEST(CoreReplayTest, EntriesThatReferToNothingAreErrors) {
  const World w = Chu();
  auto replay = CoreReplay::Create(SetupOf(w, Config()));
  ASSERT_TRUE(replay.ok());
  JournalEntry apply{1, {}, ""};
  apply.input.kind = CoreInput::Kind::kApply;
  apply.input.ref = 7;
  auto out = (*replay)->Feed(apply);
  ASSERT_FALSE(out.ok());
  EXPECT_NE(out.error().message.find("no change from entry 7"), std::string::npos) << out.error().message;
  JournalEntry awards{2, {}, ""};
  awards.input.kind = CoreInput::Kind::kPlanAwards;
  awards.input.ref = 1;
  EXPECT_FALSE((*replay)->Feed(awards).ok());
  JournalEntry add{3, {}, ""};
  add.input.kind = CoreInput::Kind::kAddOrder;  // without its order
  EXPECT_FALSE((*replay)->Feed(add).ok());
  ReplaySetup bad = SetupOf(w, Config());
  bad.strategy = "fastest";
  EXPECT_FALSE(CoreReplay::Create(bad).ok());
}

}  // namespace
}  // namespace dispatch::engine::testing
