// The dispatcher loop's timing and batching parts on their own: the command queue
// (command_queue.h), what a batch owes the outside world and when the snapshot is published
// (batch_effects.h), the dispatch clock (dispatch_clock.h), when rounds run
// (round_schedule.h), distance sampling (distance_watch.h) and memory trimming
// (memory_trim.h).
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "server/batch_effects.h"
#include "server/command_queue.h"
#include "server/dispatch_clock.h"
#include "server/distance_watch.h"
#include "server/memory_trim.h"
#include "server/round_schedule.h"

namespace dispatch::server {
namespace {

TEST(CommandQueueTest, ABatchIsEverythingQueuedInOrderAndSaysWhenTheQueueStopped) {
  using Clock = CommandQueue::Clock;
  CommandQueue queue;
  // Nothing queued: Take returns at its wake time, empty.
  CommandQueue::Batch idle = queue.Take(Clock::now() + std::chrono::milliseconds(1));
  EXPECT_TRUE(idle.commands.empty());
  EXPECT_FALSE(idle.stopping);
  std::vector<int> ran;
  for (int i = 0; i < 3; ++i) queue.Post([&ran, i] { ran.push_back(i); });
  CommandQueue::Batch batch = queue.Take(Clock::now() + std::chrono::hours(1));  // returns at once
  ASSERT_EQ(batch.commands.size(), 3u);
  for (auto& command : batch.commands) command();
  EXPECT_EQ(ran, (std::vector<int>{0, 1, 2}));
  EXPECT_TRUE(queue.empty());
  // A command posted from another thread wakes a Take that would wait an hour.
  std::thread poster([&queue] { queue.Post([] {}); });
  EXPECT_EQ(queue.Take(Clock::now() + std::chrono::hours(1)).commands.size(), 1u);
  poster.join();
  // Stopped: Take returns at once, and what is posted later is still taken.
  queue.Stop();
  EXPECT_TRUE(queue.stopping());
  EXPECT_TRUE(queue.Take(Clock::now() + std::chrono::hours(1)).stopping);
  queue.Post([] {});
  EXPECT_FALSE(queue.empty());
  CommandQueue::Batch last = queue.Take(Clock::now() + std::chrono::hours(1));
  EXPECT_EQ(last.commands.size(), 1u);
  EXPECT_TRUE(last.stopping);
}

TEST(BatchEffectsTest, AnnouncementsWaitForThePublishAndRobotMessagesDoNotForceOne) {
  using Clock = BatchEffects::Clock;
  const Clock::time_point t0 = Clock::now();
  BatchEffects effects;
  EXPECT_TRUE(effects.PublishDue(t0));  // nothing published yet
  effects.Published(t0);
  EXPECT_FALSE(effects.changed());
  EXPECT_FALSE(effects.PublishDue(t0 + std::chrono::hours(1)));  // nothing changed
  EXPECT_EQ(effects.WakeBy(t0 + std::chrono::seconds(1)), t0 + std::chrono::seconds(1));
  // A robot report changed the state and a grant goes out: the snapshot waits for kPublishEvery.
  std::vector<std::string> out;
  effects.MarkChanged();
  effects.Defer([&out] { out.push_back("grant"); }, /*after_publish=*/false);
  EXPECT_FALSE(effects.PublishDue(t0 + std::chrono::milliseconds(5)));
  EXPECT_TRUE(effects.PublishDue(t0 + BatchEffects::kPublishEvery));
  EXPECT_EQ(effects.WakeBy(t0 + std::chrono::seconds(1)), t0 + BatchEffects::kPublishEvery);
  // A reply announces the change: publish now.
  effects.Defer([&out] { out.push_back("reply"); }, /*after_publish=*/true);
  EXPECT_TRUE(effects.PublishDue(t0 + std::chrono::milliseconds(5)));
  EXPECT_TRUE(out.empty());  // nothing leaves before the end of the batch
  effects.Published(t0 + std::chrono::milliseconds(5));
  effects.RunDeferred();
  EXPECT_EQ(out, (std::vector<std::string>{"grant", "reply"}));
  // An effect that defers another leaves it for the next batch; the reply waited for is gone.
  effects.Defer([&] { effects.Defer([&out] { out.push_back("later"); }, false); }, false);
  effects.RunDeferred();
  EXPECT_EQ(out.size(), 2u);
  effects.MarkChanged();
  EXPECT_FALSE(effects.PublishDue(t0 + std::chrono::milliseconds(6)));
  effects.RunDeferred();
  EXPECT_EQ(out.back(), "later");
}

// A publish that took long (many robots) spaces the next ones nobody waits for, to
// kPublishShare times its time; a reply still publishes at once; a quick publish brings the
// period back.
TEST(BatchEffectsTest, ASlowPublishSpacesThoseNobodyWaitsFor) {
  using Clock = BatchEffects::Clock;
  using std::chrono::milliseconds;
  const Clock::time_point t0 = Clock::now();
  BatchEffects effects;
  effects.Published(t0, milliseconds(5));
  EXPECT_EQ(effects.period(), milliseconds(5) * BatchEffects::kPublishShare);
  effects.MarkChanged();
  EXPECT_FALSE(effects.PublishDue(t0 + BatchEffects::kPublishEvery));
  EXPECT_EQ(effects.WakeBy(t0 + std::chrono::seconds(1)), t0 + milliseconds(50));
  EXPECT_TRUE(effects.PublishDue(t0 + milliseconds(50)));
  effects.Defer([] {}, /*after_publish=*/true);
  EXPECT_TRUE(effects.PublishDue(t0 + milliseconds(1)));
  effects.Published(t0 + milliseconds(1), std::chrono::microseconds(300));
  effects.RunDeferred();
  EXPECT_EQ(effects.period(), BatchEffects::kPublishEvery);
  effects.MarkChanged();
  EXPECT_TRUE(effects.PublishDue(t0 + milliseconds(1) + BatchEffects::kPublishEvery));
}

// Journal events wait for the next publish, in order, without hastening it; a reply's publish
// lets them out too, after the batch's other effects.
TEST(BatchEffectsTest, AnnouncementsGoOutAfterTheNextPublishWithoutHasteningIt) {
  using Clock = BatchEffects::Clock;
  using std::chrono::milliseconds;
  const Clock::time_point t0 = Clock::now();
  BatchEffects effects;
  effects.Published(t0);
  std::vector<std::string> out;
  effects.MarkChanged();
  effects.Announce([&out] { out.push_back("event 1"); });
  effects.Announce([&out] { out.push_back("event 2"); });
  effects.Defer([&out] { out.push_back("grant"); }, /*after_publish=*/false);
  EXPECT_FALSE(effects.PublishDue(t0 + milliseconds(5)));
  effects.RunDeferred();
  EXPECT_EQ(out, (std::vector<std::string>{"grant"})) << "the events wait for the snapshot";
  EXPECT_EQ(effects.WakeBy(t0 + std::chrono::seconds(1)), t0 + BatchEffects::kPublishEvery);
  ASSERT_TRUE(effects.PublishDue(t0 + BatchEffects::kPublishEvery));
  effects.Published(t0 + BatchEffects::kPublishEvery);
  effects.Announce([&out] { out.push_back("event 3"); });  // after the publish: the next one's
  effects.RunDeferred();
  EXPECT_EQ(out, (std::vector<std::string>{"grant", "event 1", "event 2"}));
  // A reply forces the publish; the event announced before it goes out with it, after it.
  effects.MarkChanged();
  effects.Defer([&out] { out.push_back("reply"); }, /*after_publish=*/true);
  EXPECT_TRUE(effects.PublishDue(t0 + BatchEffects::kPublishEvery + milliseconds(1)));
  effects.Published(t0 + BatchEffects::kPublishEvery + milliseconds(1));
  effects.RunDeferred();
  EXPECT_EQ(out, (std::vector<std::string>{"grant", "event 1", "event 2", "reply", "event 3"}));
}

TEST(DispatchClockTest, GoesOnFromTheStoredTimeAtItsScale) {
  using Clock = DispatchClock::Clock;
  const Clock::time_point start{};
  DispatchClock clock(5.0, start);
  EXPECT_DOUBLE_EQ(clock.At(start + std::chrono::seconds(2)), 10.0);
  clock.ContinueFrom(100.0);
  clock.ContinueFrom(40.0);  // never back
  EXPECT_DOUBLE_EQ(clock.At(start), 100.0);
  EXPECT_DOUBLE_EQ(clock.At(start + std::chrono::seconds(2)), 110.0);
  // Dispatcher second 120 comes 4 wall seconds after the start; one already past comes now.
  EXPECT_EQ(clock.WallAt(120.0, start), start + std::chrono::seconds(4));
  EXPECT_EQ(clock.WallAt(90.0, start + std::chrono::seconds(1)), start + std::chrono::seconds(1));
  EXPECT_EQ(WallDuration(0.25), std::chrono::milliseconds(250));
}

TEST(RoundScheduleTest, OneRoundAtATimeAndWhatBecameDueMeanwhileRunsAfterIt) {
  RoundSchedule rounds;
  EXPECT_FALSE(rounds.due());
  rounds.MarkDue();
  ASSERT_TRUE(rounds.Begin());
  EXPECT_FALSE(rounds.due());
  rounds.Started(0.0);
  // Due again while the round runs: not now, once it is committed.
  rounds.MarkDue();
  EXPECT_FALSE(rounds.Begin());
  EXPECT_FALSE(rounds.due());
  rounds.Finished();
  EXPECT_TRUE(rounds.due());
  ASSERT_TRUE(rounds.Begin());  // the core had nothing to allocate: no round starts
  EXPECT_FALSE(rounds.running());
  rounds.Finished();
  EXPECT_FALSE(rounds.due());
  // An award that did not hold: another round after this one.
  ASSERT_TRUE(rounds.Begin());
  rounds.Started(0.0);
  rounds.Again();
  rounds.Finished();
  EXPECT_TRUE(rounds.due());
  // A store failure: the next tick makes a round due, until a round begins.
  ASSERT_TRUE(rounds.Begin());
  rounds.Retry();
  rounds.Tick();
  EXPECT_TRUE(rounds.due());
  ASSERT_TRUE(rounds.Begin());
  rounds.Tick();
  EXPECT_FALSE(rounds.due());
}

TEST(RoundScheduleTest, ABatchWindowHoldsADueRoundUntilItEnds) {
  RoundSchedule rounds;
  rounds.MarkDue();
  EXPECT_FALSE(rounds.Waiting(0.0));  // no window: never waits
  rounds.SetWindow(2.0);
  EXPECT_FALSE(rounds.Waiting(0.0));  // no round yet: the first one starts at once
  ASSERT_TRUE(rounds.Begin());
  rounds.Started(10.0);
  rounds.Finished();
  EXPECT_FALSE(rounds.Waiting(10.5));  // nothing due
  rounds.MarkDue();
  EXPECT_TRUE(rounds.Waiting(10.5));
  EXPECT_TRUE(rounds.Waiting(11.99));
  EXPECT_DOUBLE_EQ(rounds.not_before(), 12.0);
  EXPECT_TRUE(rounds.due());  // still due while it waits
  EXPECT_FALSE(rounds.Waiting(12.0));
  ASSERT_TRUE(rounds.Begin());
  // A round with nothing to allocate does not start a window.
  rounds.Finished();
  rounds.MarkDue();
  EXPECT_FALSE(rounds.Waiting(12.5));
}

TEST(DistanceWatchTest, SamplesAtMostEveryFiftyMillisecondsAndTellsAChange) {
  using Clock = DistanceWatch::Clock;
  const Clock::time_point t0 = Clock::now();
  DistanceWatch watch;
  EXPECT_TRUE(watch.SampleDue(t0));
  EXPECT_FALSE(watch.SampleDue(t0 + std::chrono::milliseconds(49)));
  EXPECT_TRUE(watch.SampleDue(t0 + DistanceWatch::kSampleEvery));
  engine::MinDistance closest;
  EXPECT_FALSE(watch.Update(closest));  // none seen yet, as before
  closest.distance = 0.8;
  closest.a = "R1";
  closest.b = "R2";
  closest.time = 3.0;
  EXPECT_TRUE(watch.Update(closest));
  EXPECT_FALSE(watch.Update(closest));
  EXPECT_EQ(watch.closest().a, "R1");
  closest.time = 4.0;  // as close again, later
  EXPECT_TRUE(watch.Update(closest));
}

TEST(MemoryTrimTest, TrimsAtOnceThenAtMostEveryTenSeconds) {
  using Clock = MemoryTrim::Clock;
  const Clock::time_point t0 = Clock::now();
  MemoryTrim trim;
  {
    std::vector<std::unique_ptr<char[]>> blocks;  // something freed for it to give back
    for (int i = 0; i < 64; ++i) blocks.push_back(std::make_unique<char[]>(64 * 1024));
  }
  EXPECT_TRUE(trim.Tick(t0));
  EXPECT_FALSE(trim.Tick(t0 + std::chrono::seconds(9)));
  EXPECT_TRUE(trim.Tick(t0 + MemoryTrim::kEvery));
  EXPECT_FALSE(trim.Tick(t0 + MemoryTrim::kEvery + std::chrono::seconds(1)));
}

}  // namespace
}  // namespace dispatch::server
