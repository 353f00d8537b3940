// BIT2024's task allocation (seed 003 steps 1-5): the encoding's blocks, eq. (1), PSO-GA
// against the exact optimum on tiny batches and against plain PSO and GA on the same budget.
// Points are grid cells (x = id / 100, y = id % 100) and distances Manhattan, so the batches
// need no map.
#include "engine/allocation/swarm_allocation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <numeric>
#include <random>
#include <vector>

namespace dispatch::engine {
namespace {

double Manhattan(PointId a, PointId b) { return std::abs(a / 100 - b / 100) + std::abs(a % 100 - b % 100); }

// n robots and m tasks on a 20 x 20 grid, random headings in quarter turns.
SwarmProblem RandomBatch(std::uint64_t seed, std::size_t n, std::size_t m) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> cell(0, 19), quarter(0, 3);
  auto point = [&] { return static_cast<PointId>(cell(rng) * 100 + cell(rng)); };
  SwarmProblem p;
  for (std::size_t k = 0; k < n; ++k) p.robots.push_back({point(), quarter(rng) * std::numbers::pi / 2});
  for (std::size_t j = 0; j < m; ++j) p.tasks.push_back({point(), quarter(rng) * std::numbers::pi / 2});
  p.distance = Manhattan;
  return p;
}

std::vector<double> Distances(const SwarmProblem& p) {
  const std::size_t n = p.robots.size(), m = p.tasks.size();
  std::vector<double> d((n + m) * m);
  for (std::size_t r = 0; r < n + m; ++r) {
    for (std::size_t j = 0; j < m; ++j) d[r * m + j] = Manhattan(r < n ? p.robots[r].start : p.tasks[r - n].end_point(), p.tasks[j].point);
  }
  return d;
}

// Every task exactly once, at most a block's size per robot.
void ExpectCompletePlan(const SwarmPlan& plan, std::size_t n, std::size_t m) {
  ASSERT_EQ(plan.sequences.size(), n);
  const std::vector<std::size_t> blocks = SwarmBlocks(m, n);
  std::vector<int> seen(m, 0);
  for (std::size_t k = 0; k < n; ++k) {
    EXPECT_LE(plan.sequences[k].size(), blocks[k + 1] - blocks[k]);
    for (std::size_t t : plan.sequences[k]) ++seen.at(t);
  }
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int c) { return c == 1; }));
}

TEST(SwarmAllocationTest, BlocksAreEqualAndRoundedUpTheRestIdleSlots) {
  EXPECT_EQ(SwarmBlocks(6, 3), (std::vector<std::size_t>{0, 2, 4, 6}));
  EXPECT_EQ(SwarmBlocks(7, 3), (std::vector<std::size_t>{0, 3, 6, 9}));
  EXPECT_EQ(SwarmBlocks(2, 3), (std::vector<std::size_t>{0, 1, 2, 3}));
}

// Fewer tasks than robots: the tasks go to the robots nearest them whatever their order (the
// idle slots let any robot idle; without them robots 0 and 1, far away, would do both), and a
// task's end and length count.
TEST(SwarmAllocationTest, IdleSlotsLetAnyRobotIdleAndTasksEndWhereTheyEnd) {
  SwarmProblem p;
  p.robots = {{1919, 0.0}, {1918, 0.0}, {0, 0.0}, {1001, 0.0}};
  p.tasks = {{0, 0.0, 10, 10.0}, {1000, 0.0}};  // (0,0) -> (0,10), 10 long; at (10,0)
  p.distance = Manhattan;
  SwarmProblem one = p;  // robot 2 alone: task 0, then from its end (0,10) to task 1
  one.robots = {p.robots[2]};
  SwarmPlan by_hand;
  SwarmFitness(one, Distances(one), {0, 1}, &by_hand);
  EXPECT_DOUBLE_EQ(by_hand.f_all, 0.0 + 10.0 + 20.0);
  SwarmOptions o;
  o.particles = 10;
  o.evaluations = 400;
  const auto plan = PlanSwarm(p, o);
  ASSERT_TRUE(plan.ok()) << plan.error().message;
  ExpectCompletePlan(*plan, 4, 2);
  EXPECT_EQ(plan->sequences[2], (std::vector<std::size_t>{0}));
  EXPECT_EQ(plan->sequences[3], (std::vector<std::size_t>{1}));
  EXPECT_DOUBLE_EQ(plan->f_all, 10.0 + 1.0);
  EXPECT_DOUBLE_EQ(plan->f_min, 0.0);  // idle robots travel nothing
  SwarmProblem bad = p;
  bad.tasks[0].length = -1.0;
  EXPECT_FALSE(PlanSwarm(bad, o).ok());
}

// Eq. (1) by hand: robot 0 at (0,0) heading east does t1 then t0, robot 1 at (10,0) does t2.
TEST(SwarmAllocationTest, FitnessIsEquationOne) {
  const double pi = std::numbers::pi;
  SwarmProblem p;
  p.robots = {{0, 0.0}, {1000, 0.0}};
  p.tasks = {{200, pi / 2}, {500, 0.0}, {1200, pi}};
  p.distance = Manhattan;
  p.a1 = 2.0;
  p.a2 = 1.0;
  p.a3 = 3.0;
  SwarmPlan plan;
  const double f = SwarmFitness(p, Distances(p), {1, 0, 2, 3}, &plan);  // 3 is robot 1's idle slot
  EXPECT_DOUBLE_EQ(plan.f_all, 5.0 + 3.0 + 2.0);
  EXPECT_DOUBLE_EQ(plan.f_min, 2.0);
  EXPECT_DOUBLE_EQ(plan.f_switch, pi / 2 + pi);  // 0 -> 0 -> pi/2, and 0 -> pi
  EXPECT_DOUBLE_EQ(f, 2.0 * 2.0 + 10.0 + 3.0 * 1.5 * pi);
  EXPECT_EQ(SwarmFitness(p, Distances(p), {1, 0, 2}), std::numeric_limits<double>::infinity());  // no idle slot
}

// Tiny batches (2 robots, 6 tasks: 720 plans, all tried): PSO-GA never beats the optimum (the
// same encoding) and, within 1,500 evaluations, finds it on most seeds and stays within 25% of
// it on the others (measured: 15 of 20, worst gap 19.1%).
TEST(SwarmAllocationTest, OnTinyBatchesPsoGaReachesTheExactOptimumMostOfTheTime) {
  int optimal = 0;
  double worst_gap = 0.0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const SwarmProblem p = RandomBatch(seed, 2, 6);
    const std::vector<double> dist = Distances(p);
    std::vector<std::size_t> perm(6);
    std::iota(perm.begin(), perm.end(), 0);
    double best = std::numeric_limits<double>::infinity();
    do {
      best = std::min(best, SwarmFitness(p, dist, perm));
    } while (std::next_permutation(perm.begin(), perm.end()));
    SwarmOptions o;
    o.seed = seed;
    o.particles = 20;
    o.evaluations = 1500;
    const auto plan = PlanSwarm(p, o);
    ASSERT_TRUE(plan.ok()) << plan.error().message;
    ExpectCompletePlan(*plan, 2, 6);
    EXPECT_GE(plan->fitness, best - 1e-9);
    EXPECT_LE(plan->evaluations, 1500u);
    if (plan->fitness <= best + 1e-9) ++optimal;
    worst_gap = std::max(worst_gap, plan->fitness / best - 1.0);
  }
  std::printf("tiny batches: optimum on %d of 20 seeds, worst gap %.1f%%\n", optimal, 100.0 * worst_gap);
  EXPECT_GE(optimal, 13);
  EXPECT_LE(worst_gap, 0.25);
}

// The patent's claim, on random batches (5 robots, 30 tasks, 20 seeds, the same encoding and
// the same number of fitness evaluations): PSO-GA's mean fitness is at least as good as plain
// PSO's. It is NOT as good as plain GA's (measured 328.0 against 227.3, printed here): eq. (2)
// moves task numbers arithmetically, and a value between two task numbers is an unrelated
// task, so the swarm step scrambles the particles the genetic step then ranks; the README's
// allocation section has the figures.
TEST(SwarmAllocationTest, PsoGaIsAtLeastAsGoodAsPsoOnTheSameBudget) {
  double mean[3] = {0.0, 0.0, 0.0};
  const SwarmMethod methods[3] = {SwarmMethod::kPsoGa, SwarmMethod::kPso, SwarmMethod::kGa};
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const SwarmProblem p = RandomBatch(100 + seed, 5, 30);
    for (int k = 0; k < 3; ++k) {
      SwarmOptions o;
      o.method = methods[k];
      o.seed = seed;
      o.evaluations = 6000;
      const auto plan = PlanSwarm(p, o);
      ASSERT_TRUE(plan.ok()) << plan.error().message;
      ExpectCompletePlan(*plan, 5, 30);
      EXPECT_LE(plan->evaluations, 6000u);
      mean[k] += plan->fitness / 20.0;
    }
  }
  std::printf("5 robots, 30 tasks, 6000 evaluations, mean of 20 seeds: psoga %.1f, pso %.1f, ga %.1f\n", mean[0], mean[1],
              mean[2]);
  EXPECT_LE(mean[0], mean[1]);
}

TEST(SwarmAllocationTest, SeededCancellableAndBadInputsAreRefused) {
  const SwarmProblem p = RandomBatch(7, 3, 12);
  SwarmOptions o;
  o.seed = 5;
  const auto a = PlanSwarm(p, o), b = PlanSwarm(p, o);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->sequences, b->sequences);
  EXPECT_EQ(a->fitness, b->fitness);
  EXPECT_FALSE(a->stopped);
  o.cancelled = [] { return true; };
  const auto cancelled = PlanSwarm(p, o);
  ASSERT_TRUE(cancelled.ok());
  EXPECT_TRUE(cancelled->stopped);
  EXPECT_EQ(cancelled->iterations, 0u);
  EXPECT_EQ(cancelled->evaluations, o.particles);  // the initial swarm only
  ExpectCompletePlan(*cancelled, 3, 12);
  o.cancelled = {};
  o.deadline = std::chrono::steady_clock::now();
  EXPECT_TRUE(PlanSwarm(p, o)->stopped);

  SwarmProblem bad = p;
  bad.robots.clear();
  EXPECT_FALSE(PlanSwarm(bad, SwarmOptions{}).ok());
  bad = p;
  bad.tasks.clear();
  EXPECT_FALSE(PlanSwarm(bad, SwarmOptions{}).ok());
  bad = p;
  bad.distance = {};
  EXPECT_FALSE(PlanSwarm(bad, SwarmOptions{}).ok());
  bad = p;
  bad.distance = [](PointId, PointId) { return -1.0; };
  EXPECT_FALSE(PlanSwarm(bad, SwarmOptions{}).ok());
  SwarmOptions one;
  one.particles = 1;
  EXPECT_FALSE(PlanSwarm(p, one).ok());
  SwarmOptions odd;
  odd.mutation = 1.5;
  EXPECT_FALSE(PlanSwarm(p, odd).ok());
}

}  // namespace
}  // namespace dispatch::engine
