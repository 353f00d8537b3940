// Model test of the auction's bid computation: AuctionAllocator::ComputeBids and
// ComputeReachBids against a straightforward reference written here from their contract
// (Chu2024 eqs. (2)-(8)): the candidate route sampled with RouteSampler (leg from the queue's
// end to the first pick, then the order's own route from the arrival), every sample priced by
// TrafficPredictor::Density (ZoneAt + CountAt of the other robots). Every field of every Bid
// must be equal (==, no tolerance) on random fleets of grid floors and the Chu2024 floor,
// under several prediction / sampling settings, round after round of awards. On a lazy route
// table the flow bounds take each robot's leg cost as its time to the first pick: the costs are
// checked to be the sampler's times, and the pruned awards the same as with the sampler's walk.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "allocation_test_util.h"
#include "engine/allocation/auction_allocator.h"
#include "engine/allocation/route_sampler.h"
#include "engine/map/chu2024_floor.h"

namespace dispatch::engine {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

Bid Unreachable(const std::string& robot, double ready) {
  Bid b;
  b.robot = robot;
  b.reachable = false;
  b.t_d = b.t_w = b.t_t = b.bid = kInf;
  b.ready_time = ready;
  return b;
}

void Fill(const AllocationConfig& c, const DensityTerm& d, Bid& b) {
  b.t_t = b.t_d + b.t_w;
  b.flow = d.flow;
  b.peaks = d.peaks;
  b.x = c.zeta * b.flow;
  b.bid = BidValue(c.alpha, c.beta, b.t_t, b.t_d, b.x);
}

// The reference of ComputeBids: one robot at a time, every sample through Density.
std::vector<Bid> ReferenceBids(const FleetState& state, const PlanTask& task) {
  const AllocationConfig& c = state.config();
  RouteSampler sampler(state.map(), state.routes(), c.speed, c.sample_step);
  std::vector<RouteSample> shared;
  sampler.AppendTask(task, 0.0, shared);
  const double task_travel = state.TaskTravelTime(task);
  const double task_work = TaskWorkTime(task);
  const PointId first = task.picks.front();
  std::vector<Bid> bids;
  for (std::size_t i = 0; i < state.robot_count(); ++i) {
    const QueueSummary& s = state.summary(i);
    const double leg = state.routes().Cost(s.end_point, first);
    std::vector<RouteSample> samples;
    const double arrival = sampler.AppendLeg(s.end_point, first, s.end_time, samples);
    if (!std::isfinite(leg) || !std::isfinite(arrival) || !std::isfinite(task_travel)) {
      bids.push_back(Unreachable(state.robot_id(i), s.end_time));
      continue;
    }
    for (const RouteSample& r : shared) samples.push_back({r.xy, r.t + arrival});
    Bid b;
    b.robot = state.robot_id(i);
    b.ready_time = s.end_time;
    b.t_d = s.travel_time + leg + task_travel;
    b.t_w = s.work_time + task_work;
    Fill(c, state.predictor().Density(samples, b.robot), b);
    bids.push_back(b);
  }
  return bids;
}

// The reference of ComputeReachBids: the leg plus the first pick on arrival.
std::vector<Bid> ReferenceReachBids(const FleetState& state, PointId first) {
  const AllocationConfig& c = state.config();
  RouteSampler sampler(state.map(), state.routes(), c.speed, c.sample_step);
  std::vector<Bid> bids;
  for (std::size_t i = 0; i < state.robot_count(); ++i) {
    const QueueSummary& s = state.summary(i);
    const double leg = state.routes().Cost(s.end_point, first);
    std::vector<RouteSample> samples;
    const double arrival = sampler.AppendLeg(s.end_point, first, s.end_time, samples);
    if (!std::isfinite(leg) || !std::isfinite(arrival)) {
      bids.push_back(Unreachable(state.robot_id(i), s.end_time));
      continue;
    }
    samples.push_back({state.map().point(first).position, arrival});
    Bid b;
    b.robot = state.robot_id(i);
    b.ready_time = s.end_time;
    b.t_d = s.travel_time + leg;
    b.t_w = s.work_time;
    Fill(c, state.predictor().Density(samples, b.robot), b);
    bids.push_back(b);
  }
  return bids;
}

// Bit-identical, field by field (NaN never occurs: unreachable terms are +infinity).
void ExpectSameBids(const std::vector<Bid>& got, const std::vector<Bid>& want,
                    const std::string& where) {
  ASSERT_EQ(got.size(), want.size()) << where;
  for (std::size_t i = 0; i < got.size(); ++i) {
    const Bid& g = got[i];
    const Bid& w = want[i];
    SCOPED_TRACE(where + " robot " + w.robot);
    EXPECT_EQ(g.robot, w.robot);
    EXPECT_EQ(g.reachable, w.reachable);
    EXPECT_EQ(g.t_d, w.t_d);
    EXPECT_EQ(g.t_w, w.t_w);
    EXPECT_EQ(g.t_t, w.t_t);
    EXPECT_EQ(g.flow, w.flow);
    EXPECT_EQ(g.x, w.x);
    EXPECT_EQ(g.bid, w.bid);
    EXPECT_EQ(g.ready_time, w.ready_time);
    EXPECT_EQ(g.peaks, w.peaks);
  }
}

struct Floor {
  std::shared_ptr<const WarehouseMap> map;
  std::shared_ptr<const RouteTable> routes;
  std::vector<PointId> picks, drops;
};

Floor MakeFloor(std::shared_ptr<const WarehouseMap> map) {
  Floor f;
  f.map = std::move(map);
  f.routes = testing_util::Routes(f.map);
  for (std::size_t i = 0; i < f.map->point_count(); ++i) {
    const auto kind = f.map->point(static_cast<PointId>(i)).kind;
    if (kind == PointKind::kPick) f.picks.push_back(static_cast<PointId>(i));
    if (kind == PointKind::kDrop) f.drops.push_back(static_cast<PointId>(i));
  }
  return f;
}

// A grid floor like allocation_bench's (what ParseMovingAiMap builds: a point every metre,
// single bidirectional lanes between 4-neighbours, tile_cells x tile_cells zones clipped to
// the floor [-0.5, size - 0.5]^2), with a few blocked cells so routes bend. Built here with
// MapBuilder because the importer lives in dispatch_engine_io.
Floor TiledGridFloor(int size, int tile_cells, unsigned seed) {
  std::mt19937 rng(seed);
  const std::size_t n = static_cast<std::size_t>(size);
  std::vector<std::string> rows(n, std::string(n, '.'));  // rows[y][x]
  for (int k = 0; k < size; ++k) rows[1 + rng() % (n - 1)][rng() % n] = '@';
  for (int k = 0; k < 12; ++k) rows[1 + rng() % (n - 1)][rng() % n] = 'S';
  for (int k = 0; k < 4; ++k) rows[0][rng() % n] = 'E';
  MapBuilder b("grid");
  b.SetFloor({-0.5, -0.5}, {size - 0.5, size - 0.5});
  for (int ty = 0; ty * tile_cells < size; ++ty) {
    for (int tx = 0; tx * tile_cells < size; ++tx) {
      b.AddRectZone("t" + std::to_string(ty) + "_" + std::to_string(tx),
                    {tx * tile_cells - 0.5, ty * tile_cells - 0.5},
                    {std::min(size, (tx + 1) * tile_cells) - 0.5,
                     std::min(size, (ty + 1) * tile_cells) - 0.5});
    }
  }
  auto free = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < size && y < size &&
           rows[static_cast<std::size_t>(y)][static_cast<std::size_t>(x)] != '@';
  };
  auto name = [](int x, int y) { return std::to_string(x) + "," + std::to_string(y); };
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      if (!free(x, y)) continue;
      const char c = rows[static_cast<std::size_t>(y)][static_cast<std::size_t>(x)];
      b.AddPoint(name(x, y), {static_cast<double>(x), static_cast<double>(y)},
                 c == 'S' ? PointKind::kPick : c == 'E' ? PointKind::kDrop : PointKind::kLane);
    }
  }
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      if (!free(x, y)) continue;
      if (free(x + 1, y)) b.AddPath(name(x, y), name(x + 1, y), std::nullopt, 0.0, true);
      if (free(x, y + 1)) b.AddPath(name(x, y), name(x, y + 1), std::nullopt, 0.0, true);
    }
  }
  MapBuildOptions options;
  options.check_service_connectivity = false;  // an isolated cell only makes bids unreachable
  return MakeFloor(testing_util::Share(b.Build(options)));
}

// A grid whose spacing is not a multiple of the sample step, so samples fall anywhere.
Floor OddGridFloor() {
  return MakeFloor(testing_util::Grid(9, 7, 1.3, 3, {{1, 5}, {6, 6}, {3, 3}, {8, 1}, {2, 0}},
                                      {{0, 6}, {8, 6}, {0, 0}}));
}

Floor Chu2024() {
  return MakeFloor(std::make_shared<const WarehouseMap>(BuildChu2024Floor().value()));
}

std::vector<AllocationConfig> Configs() {
  std::vector<AllocationConfig> configs(4);
  // [0]: defaults (h = 0.5 m, 0.5 s buckets, hold 300 s).
  configs[1].sample_step = 0.37;  // samples off the bucket grid
  configs[1].traffic.bucket_seconds = 0.3;
  configs[1].traffic.origin_time = 1.7;
  configs[1].hold_seconds = 0.0;
  configs[2].traffic.bucket_seconds = 0.1;  // several buckets per sample
  configs[2].traffic.zone_cell_size = 0.7;  // coarse zone grid: many partial cells
  configs[2].speed = 1.0;
  configs[3].sample_step = 1.0 / 3.0;
  configs[3].traffic.origin_time = -4.25;
  configs[3].hold_seconds = 20.0;
  return configs;
}

Order RandomOrder(const Floor& f, std::mt19937& rng, int k) {
  Order o;
  o.id = o.client_id = "o" + std::to_string(k);
  o.picks = {f.picks[rng() % f.picks.size()]};
  if (rng() % 3 == 0) o.picks.push_back(f.picks[rng() % f.picks.size()]);
  o.drop = f.drops[rng() % f.drops.size()];
  o.work_time = (rng() % 2 == 0) ? 5.0 : 2.25;
  o.created_time = k;
  o.formation = rng() % 5 == 0;
  return o;
}

// Random fleets on `floor`: robots at random points with random (some fractional, some on a
// bucket edge) ready times; rounds of awards, every round's bids checked before the award.
void CheckFloor(const Floor& floor, const std::string& name, int robots, int rounds,
                unsigned seed) {
  const std::vector<AllocationConfig> configs = Configs();
  for (std::size_t ci = 0; ci < configs.size(); ++ci) {
    std::mt19937 rng(seed + static_cast<unsigned>(ci));
    std::vector<FleetRobot> fleet_robots;
    for (int i = 0; i < robots; ++i) {
      const double ready = rng() % 2 == 0 ? 0.5 * static_cast<double>(rng() % 20)
                                          : std::uniform_real_distribution<double>(0, 9)(rng);
      fleet_robots.push_back({"R" + std::to_string(i + 1),
                              static_cast<PointId>(rng() % floor.map->point_count()), ready});
    }
    FleetState state =
        testing_util::MakeFleet(floor.map, floor.routes, fleet_robots, configs[ci]);
    AuctionAllocator auction;
    for (int k = 0; k < rounds; ++k) {
      const Order order = RandomOrder(floor, rng, k);
      const PlanTask task = state.TaskOf(order.picks, order.drop, order.work_time);
      const std::string where = name + " config " + std::to_string(ci) + " round " +
                                std::to_string(k);
      ExpectSameBids(auction.ComputeBids(state, task), ReferenceBids(state, task), where);
      ExpectSameBids(auction.ComputeReachBids(state, task.picks.front()),
                     ReferenceReachBids(state, task.picks.front()), where + " reach");
      if (::testing::Test::HasFailure()) return;
      auto award = auction.Allocate(order, state);
      ASSERT_TRUE(award.ok()) << where << ": " << award.error().message;
    }
  }
}

TEST(AuctionEquivalenceTest, BenchLikeGridMatchesReference) {
  CheckFloor(TiledGridFloor(40, 10, 1), "grid40/10", 60, 12, 100);
}

TEST(AuctionEquivalenceTest, GridWithOddTilesMatchesReference) {
  CheckFloor(TiledGridFloor(31, 7, 2), "grid31/7", 40, 10, 200);
}

TEST(AuctionEquivalenceTest, OddSpacingGridMatchesReference) {
  CheckFloor(OddGridFloor(), "grid1.3", 12, 15, 300);
}

TEST(AuctionEquivalenceTest, Chu2024FloorMatchesReference) {
  CheckFloor(Chu2024(), "chu2024", 18, 15, 400);
}

// A route table that answers as `inner` but tells nothing of how it was built (so the auction
// walks the sampler for every robot's time to the first pick).
class OpaqueRoutes : public RouteTable {
 public:
  explicit OpaqueRoutes(std::shared_ptr<const RouteTable> inner) : inner_(std::move(inner)) {}
  std::size_t point_count() const override { return inner_->point_count(); }
  double Cost(PointId from, PointId to) const override { return inner_->Cost(from, to); }
  PointId NextHop(PointId from, PointId to) const override { return inner_->NextHop(from, to); }
  Result<Route> Path(PointId from, PointId to) const override { return inner_->Path(from, to); }
  std::string_view method() const override { return "opaque"; }

 private:
  std::shared_ptr<const RouteTable> inner_;
};

TEST(AuctionEquivalenceTest, ALazyTablesCostsAreTheSamplersTimesAndItsAwardsTheSame) {
  const Floor floor = TiledGridFloor(40, 10, 1);
  RouteTableOptions options;
  options.method = RouteTableMethod::kLazy;
  auto made = MakeRouteTable(floor.map, options);
  ASSERT_TRUE(made.ok()) << made.error().message;
  const std::shared_ptr<const RouteTable> lazy = std::move(made).value();
  const auto opaque = std::make_shared<const OpaqueRoutes>(lazy);
  EXPECT_TRUE(AuctionAllocator::CostsAreSampledTimes(*lazy, 1.0));
  EXPECT_FALSE(AuctionAllocator::CostsAreSampledTimes(*lazy, 2.0));
  EXPECT_FALSE(AuctionAllocator::CostsAreSampledTimes(*opaque, 1.0));
  EXPECT_FALSE(AuctionAllocator::CostsAreSampledTimes(*floor.routes, 1.0));  // a dense table
  std::mt19937 rng(500);
  RouteSampler sampler(*floor.map, *lazy, 1.0, 0.5);
  for (int k = 0; k < 400; ++k) {
    const auto from = static_cast<PointId>(rng() % floor.map->point_count());
    const auto to = static_cast<PointId>(rng() % floor.map->point_count());
    ASSERT_EQ(sampler.TimeToTarget(from, to), lazy->Cost(from, to)) << from << " -> " << to;
  }
  // The same fleet on both tables, rounds of pruned auctions (only bids that can win priced).
  std::vector<FleetRobot> robots;
  for (int i = 0; i < 60; ++i) {
    robots.push_back({"R" + std::to_string(i + 1), static_cast<PointId>(rng() % floor.map->point_count()),
                      0.5 * static_cast<double>(rng() % 20)});
  }
  FleetState a = testing_util::MakeFleet(floor.map, lazy, robots);
  FleetState b = testing_util::MakeFleet(floor.map, opaque, robots);
  AuctionAllocator on_lazy, on_opaque;
  for (int k = 0; k < 20; ++k) {
    const Order order = RandomOrder(floor, rng, k);
    auto got = on_lazy.Allocate(order, a);
    auto want = on_opaque.Allocate(order, b);
    ASSERT_TRUE(got.ok() && want.ok()) << k;
    const std::string where = "round " + std::to_string(k);
    EXPECT_EQ(got->winners, want->winners) << where;
    ExpectSameBids(got->bids, want->bids, where);
    ExpectSameBids(got->companion_bids, want->companion_bids, where + " companions");
  }
}

}  // namespace
}  // namespace dispatch::engine
