// allocation_bench: one auction round (Chu2024 §2, eqs. (1)-(8), traffic prediction on) per
// iteration: every robot bids for a new order appended to its queue, the winner (or the
// formation team, every 4th order) is awarded, and queues, plans and the prediction are
// updated. Every robot holds 2 queued tasks when an auction starts.
//
//   BM_Auction/R          R robots on a 100 x 100 grid floor (1 m cells, 10 x 10 m zones,
//                         lazy route table), each robot starting with 2 queued tasks;
//   BM_AuctionChu2024     the 18 robots of the Chu2024 floor, each with 2 queued tasks.
// Orders are drawn from a fixed set of picks and drops, so the lazy route table's
// per-destination searches are warmed up before timing starts.
#include <benchmark/benchmark.h>

#include <memory>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>

#include "engine/allocation/auction_allocator.h"
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

}  // namespace
}  // namespace dispatch::engine

BENCHMARK_MAIN();
