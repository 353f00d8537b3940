// allocation_bench: one auction round (Chu2024 §2, eqs. (1)-(8), traffic prediction on) per
// iteration: every robot bids for a new order appended to its queue, the winner (or the
// formation team, every 4th order) is awarded, and queues, plans and the prediction are
// updated. Every robot holds 2 queued tasks when an auction starts.
//
//   BM_Auction/R          R robots on a 100 x 100 grid floor (1 m cells, 10 x 10 m zones,
//                         lazy route table), each robot starting with 2 queued tasks;
//   BM_AuctionChu2024     the 18 robots of the Chu2024 floor, each with 2 queued tasks;
//   BM_PsoGa/50x18        BIT2024's PSO-GA (seed 003 steps 1-5) on a batch of 50 random
//                         single orders for the 18 robots of the Chu2024 floor (6,000 fitness
//                         evaluations, 30 particles), beside plain PSO and GA on the same
//                         budget; counters: eq. (1)'s fitness of each, and of the auction's
//                         allocation of the same batch (its queues measured by eq. (1)).
// Orders are drawn from a fixed set of picks and drops, so the lazy route table's
// per-destination searches are warmed up before timing starts.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <limits>
#include <memory>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>

#include "engine/allocation/auction_allocator.h"
#include "engine/allocation/swarm_allocation.h"
#include "engine/io/movingai_map.h"
#include "engine/map/chu2024_floor.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine {
namespace {

struct Scenario {
  std::shared_ptr<const WarehouseMap> map;
  std::shared_ptr<const RouteTable> routes;
  std::vector<PointId> picks, drops;
};

// A 100 x 100 open grid with 40 pick cells and 10 drop cells on the top row.
Scenario GridScenario() {
  std::mt19937 rng(7);
  std::vector<std::string> rows(100, std::string(100, '.'));
  for (int k = 0; k < 40; ++k) rows[1 + rng() % 98][rng() % 100] = 'S';
  for (int k = 0; k < 10; ++k) rows[0][5 + 10 * k] = 'E';
  std::string text = "type octile\nheight 100\nwidth 100\nmap\n";
  for (const auto& r : rows) text += r + "\n";
  Scenario s;
  s.map = std::make_shared<const WarehouseMap>(ParseMovingAiMap(text, "grid100").value());
  s.routes = MakeRouteTable(s.map, {}).value();
  for (std::size_t i = 0; i < s.map->point_count(); ++i) {
    const auto kind = s.map->point(static_cast<PointId>(i)).kind;
    if (kind == PointKind::kPick) s.picks.push_back(static_cast<PointId>(i));
    if (kind == PointKind::kDrop) s.drops.push_back(static_cast<PointId>(i));
  }
  for (PointId p : s.picks) benchmark::DoNotOptimize(s.routes->Cost(0, p));
  for (PointId d : s.drops) benchmark::DoNotOptimize(s.routes->Cost(0, d));
  return s;
}

Scenario Chu2024Scenario() {
  Scenario s;
  s.map = std::make_shared<const WarehouseMap>(BuildChu2024Floor().value());
  s.routes = MakeRouteTable(s.map, {}).value();
  for (std::size_t i = 0; i < s.map->point_count(); ++i) {
    const auto kind = s.map->point(static_cast<PointId>(i)).kind;
    if (kind == PointKind::kPick) s.picks.push_back(static_cast<PointId>(i));
    if (kind == PointKind::kDrop) s.drops.push_back(static_cast<PointId>(i));
  }
  return s;
}

Order RandomOrder(const Scenario& s, std::mt19937& rng, int k) {
  Order o;
  o.id = o.client_id = "o" + std::to_string(k);
  o.picks = {s.picks[rng() % s.picks.size()]};
  o.drop = s.drops[rng() % s.drops.size()];
  o.work_time = 5.0;
  o.created_time = k;
  return o;
}

// A fleet in which every robot has 2 queued tasks (the same tasks for the same seed).
FleetState QueuedFleet(const Scenario& s, const std::vector<FleetRobot>& robots) {
  std::mt19937 rng(11);
  auto fleet = FleetState::Create(s.map, s.routes, robots).value();
  for (std::size_t r = 0; r < fleet.robot_count(); ++r) {
    for (int k = 0; k < 2; ++k) {
      const Order o = RandomOrder(s, rng, k);
      if (!fleet.AssignSingle(r, "q", fleet.TaskOf(o.picks, o.drop, o.work_time)).ok()) {
        throw std::runtime_error("allocation_bench: queue setup failed");
      }
    }
  }
  return fleet;
}

// Each iteration auctions one order (every 4th a formation) among robots that all hold
// exactly 2 queued tasks: the fleet is rebuilt, untimed, after every award.
void RunAuctions(benchmark::State& state, const Scenario& s, const std::vector<FleetRobot>& robots) {
  std::mt19937 rng(5);
  std::optional<FleetState> fleet(QueuedFleet(s, robots));
  AuctionAllocator auction;
  int k = 0;
  for (auto _ : state) {
    Order order = RandomOrder(s, rng, ++k);
    order.formation = k % 4 == 0;
    auto award = auction.Allocate(order, *fleet);
    if (!award.ok()) {
      state.SkipWithError(award.error().message.c_str());
      return;
    }
    benchmark::DoNotOptimize(award.value().winners.data());
    state.PauseTiming();
    // The old fleet goes first, so the new one reuses its memory and the timed round does
    // not pay the allocator for sorting the setup's freed blocks.
    fleet.reset();
    fleet.emplace(QueuedFleet(s, robots));
    state.ResumeTiming();
  }
  state.counters["robots"] = static_cast<double>(robots.size());
  state.counters["points"] = static_cast<double>(s.map->point_count());
}

std::vector<FleetRobot> RandomRobots(const Scenario& s, int count) {
  std::mt19937 rng(3);
  std::vector<FleetRobot> robots;
  for (int i = 0; i < count; ++i) {
    robots.push_back({"R" + std::to_string(i + 1),
                      static_cast<PointId>(rng() % s.map->point_count()), 0.0});
  }
  return robots;
}

void BM_Auction(benchmark::State& state) {
  static const Scenario s = GridScenario();
  RunAuctions(state, s, RandomRobots(s, static_cast<int>(state.range(0))));
}
BENCHMARK(BM_Auction)->Arg(18)->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond);

// Only the bidding of one round, no award: the auction's core. keep = 0 prices every bid
// (F_i for every robot, as fleets up to AllocationConfig::price_every_bid_up_to get);
// keep = 2 prices only the bids that can be the winner or the runner-up (larger fleets).
void RunBids(benchmark::State& state, std::size_t keep) {
  static const Scenario s = GridScenario();
  FleetState fleet = QueuedFleet(s, RandomRobots(s, static_cast<int>(state.range(0))));
  AuctionAllocator auction;
  std::mt19937 rng(3);
  int k = 0;
  std::size_t priced = 0;
  for (auto _ : state) {
    const Order order = RandomOrder(s, rng, ++k);
    auto bids = auction.ComputeBids(fleet, fleet.TaskOf(order.picks, order.drop, order.work_time),
                                    keep);
    for (const Bid& b : bids) priced += b.priced;
    benchmark::DoNotOptimize(bids.data());
  }
  state.counters["priced"] =
      benchmark::Counter(static_cast<double>(priced), benchmark::Counter::kAvgIterations);
}
void BM_AuctionBids(benchmark::State& state) { RunBids(state, 0); }
BENCHMARK(BM_AuctionBids)->Arg(1000)->Unit(benchmark::kMillisecond);
void BM_AuctionPricedBids(benchmark::State& state) { RunBids(state, 2); }
BENCHMARK(BM_AuctionPricedBids)->Arg(1000)->Unit(benchmark::kMillisecond);

void BM_AuctionChu2024(benchmark::State& state) {
  static const Scenario s = Chu2024Scenario();
  std::vector<FleetRobot> robots;
  for (std::size_t i = 0; i < s.map->stations().size(); ++i) {
    robots.push_back({"R" + std::to_string(i + 1), s.map->stations()[i].point, 0.0});
  }
  RunAuctions(state, s, robots);
}
BENCHMARK(BM_AuctionChu2024)->Unit(benchmark::kMillisecond);

// The batch of BM_PsoGa: 50 random single orders (pick to drop) and the 18 robots of the
// Chu2024 floor at their stations; distances are the route table's drive times.
struct SwarmBatch {
  Scenario s = Chu2024Scenario();
  std::vector<FleetRobot> robots;
  std::vector<Order> orders;
  SwarmProblem problem;
};

const SwarmBatch& Batch() {
  static const SwarmBatch batch = [] {
    SwarmBatch b;
    for (std::size_t i = 0; i < b.s.map->stations().size(); ++i) {
      b.robots.push_back({"R" + std::to_string(i + 1), b.s.map->stations()[i].point, 0.0});
      b.problem.robots.push_back({b.s.map->stations()[i].point, 0.0});
    }
    std::mt19937 rng(17);
    for (int k = 0; k < 50; ++k) {
      b.orders.push_back(RandomOrder(b.s, rng, k));
      const Order& o = b.orders.back();
      b.problem.tasks.push_back({o.picks.front(), 0.0, o.drop, b.s.routes->Cost(o.picks.front(), o.drop)});
    }
    const RouteTable* routes = b.s.routes.get();
    b.problem.distance = [routes](PointId from, PointId to) { return routes->Cost(from, to); };
    return b;
  }();
  return batch;
}

// Eq. (1) of the auction's allocation of the same batch: each robot's queue in its order.
double AuctionFitness(const SwarmBatch& b, std::size_t* allocated) {
  auto fleet = FleetState::Create(b.s.map, b.s.routes, b.robots).value();
  AuctionAllocator auction;
  *allocated = 0;
  for (const auto& a : AllocateAll(auction, b.orders, fleet)) *allocated += a.award.ok();
  double f_min = std::numeric_limits<double>::infinity(), f_all = 0.0;
  for (std::size_t r = 0; r < fleet.robot_count(); ++r) {
    PointId at = b.robots[r].start;
    double travel = 0.0;
    for (const QueuedTask& q : fleet.queue(r)) {
      travel += b.s.routes->Cost(at, q.task.picks.front()) + b.s.routes->Cost(q.task.picks.front(), q.task.drop);
      at = q.task.drop;
    }
    f_min = std::min(f_min, travel);
    f_all += travel;
  }
  return b.problem.a1 * f_min + b.problem.a2 * f_all;  // headings all 0: no f_switch
}

void RunSwarm(benchmark::State& state, SwarmMethod method) {
  const SwarmBatch& b = Batch();
  SwarmOptions options;
  options.method = method;
  double fitness = 0.0;
  std::size_t evaluations = 0;
  for (auto _ : state) {
    auto plan = PlanSwarm(b.problem, options);
    if (!plan.ok()) {
      state.SkipWithError(plan.error().message.c_str());
      return;
    }
    fitness = plan->fitness;
    evaluations = plan->evaluations;
    benchmark::DoNotOptimize(plan->sequences.data());
  }
  std::size_t allocated = 0;
  state.counters["fitness"] = fitness;
  state.counters["evaluations"] = static_cast<double>(evaluations);
  state.counters["auction_fitness"] = AuctionFitness(b, &allocated);
  state.counters["auction_allocated"] = static_cast<double>(allocated);
}
void BM_PsoGa(benchmark::State& state) { RunSwarm(state, SwarmMethod::kPsoGa); }
BENCHMARK(BM_PsoGa)->Name("BM_PsoGa/50x18")->Unit(benchmark::kMillisecond);
void BM_Pso(benchmark::State& state) { RunSwarm(state, SwarmMethod::kPso); }
BENCHMARK(BM_Pso)->Name("BM_Pso/50x18")->Unit(benchmark::kMillisecond);
void BM_Ga(benchmark::State& state) { RunSwarm(state, SwarmMethod::kGa); }
BENCHMARK(BM_Ga)->Name("BM_Ga/50x18")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace dispatch::engine

BENCHMARK_MAIN();
