// Seed 004 (Wang2019) §4.3 / Table 6 on the dispatch core: h2 meets h1 head-on in a single
// lane. The controller compares the expected wait with the detour's extra time and picks the
// faster; the runs of every policy are printed.
#include "engine/sim/head_on_scenario.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

namespace dispatch::engine {
namespace {

// Seed 004 §4.3 / Table 6: h2 meets h1 head-on in a single lane. The controller compares the
// expected wait with the detour's extra time and picks the faster; both runs are printed.
TEST(HeadOnScenarioTest, Wang2019HeadOnWaitVersusReplanOnTheCore) {
  for (double work : {30.0, 5.0}) {
    auto c = RunHeadOnComparison(work);
    ASSERT_TRUE(c.ok()) << c.error().message;
    std::printf("h1 work %.0f s: wait only %.1f s, re-plan %.1f s, controller %.1f s (%s; "
                "wait estimate %.1f s, detour +%.1f s)\n",
                work, c->wait.h2_time, c->replan.h2_time, c->chosen.h2_time,
                c->chosen.replanned ? "re-plan" : "wait", c->chosen.wait_estimate,
                c->chosen.replan_extra);
    EXPECT_FALSE(c->wait.replanned);
    EXPECT_TRUE(c->replan.replanned);
    EXPECT_NEAR(c->chosen.h2_time, std::min(c->wait.h2_time, c->replan.h2_time), 1e-6);
    EXPECT_NEAR(c->replan.replan_extra, 14.0, 1e-6);  // the paper's 14 s detour
    // h1 has priority: waiting h2 never delays it (S1 -> c5 5 m, work, c5 -> V 5 m, work);
    // a detouring h2 may cross T just before it (at most that arc's time).
    const double h1_free = 5.0 + work + 5.0 + work;
    EXPECT_NEAR(c->wait.h1_time, h1_free, 1e-6);
    EXPECT_NEAR(c->chosen.h1_time, c->chosen.replanned ? c->replan.h1_time : h1_free, 1e-6);
    EXPECT_LE(c->replan.h1_time, h1_free + 2.0 + 1e-6);
  }
  auto slow = RunHeadOnComparison(30.0);
  EXPECT_TRUE(slow->chosen.replanned);              // waiting ~29 s > 14 s detour
  EXPECT_GT(slow->wait.h2_time - slow->replan.h2_time, 10.0);
  auto fast = RunHeadOnComparison(5.0);
  EXPECT_FALSE(fast->chosen.replanned);             // h1 clears the lane within seconds
  EXPECT_LT(fast->wait.h2_time, fast->replan.h2_time);
}

// Seed 004 §3.3 case ①: two robots drive at one corridor from its two ends; h2 (released
// later) reaches it first. First come, h2 enters and h1 (released first) waits at the other
// end; with head_on_priority h2 gives way at its end (waiting: the detour is 14 s longer) and
// h1 drives through as if alone: 1 s pick, 13 m, 1 s drop.
TEST(HeadOnScenarioTest, Wang2019CaseOneTheHigherPriorityPassesFirst) {
  auto c = RunCaseOneComparison();
  ASSERT_TRUE(c.ok()) << c.error().message;
  std::printf("first come: h1 %.1f s, h2 %.1f s; higher priority first: h1 %.1f s, h2 %.1f s\n", c->first_come.h1_time,
              c->first_come.h2_time, c->priority.h1_time, c->priority.h2_time);
  EXPECT_TRUE(c->first_come.h1_met_head_on);
  EXPECT_GT(c->first_come.h1_time, c->priority.h1_time + 5.0);
  EXPECT_NEAR(c->priority.h1_time, 1.0 + 13.0 + 1.0, 0.3);
  EXPECT_FALSE(c->priority.h1_met_head_on);
  EXPECT_TRUE(c->priority.h2_met_head_on);
  EXPECT_GT(c->priority.h2_time, c->first_come.h2_time);
  EXPECT_EQ(c->priority.deadlocks, 0u);
}

}  // namespace
}  // namespace dispatch::engine
