// The auction with traffic-flow prediction (Chu2024 §2.1-2.3, eqs. (1)-(8); SPEC §3.2).
//
// Every robot bids for the order appended to its queue:
//   T_d = (queue travel time) + (leg from the queue's end to the first pick) + (the order's
//         own route pick -> ... -> drop), all from the route table's Floyd costs (= S_d / v);
//   T_w = n_c * t_w + drop time over the whole queue and the order (n_c = picks, eq. (3));
//   T_t = T_d + T_w (eq. (2));  F = sum_p N_p,max / S_p over the order's candidate route,
//   sampled every h metres (RouteSampler) at the times the robot would be there, counting
//   the other robots' predicted positions (eqs. (6)-(8));  B = alpha T_t + beta T_d + zeta F
//   (eqs. (4), (5)).
// The candidate route starts where and when the robot's queue ends. In fleets up to
// AllocationConfig::price_every_bid_up_to robots F is computed for every robot, so the
// explanation holds every robot's full terms. Larger fleets price robots in increasing order
// of alpha T_t + beta T_d (<= B, since zeta F >= 0) and stop when that bound exceeds the k-th
// lowest full bid so far (k = 2 for the leader: winner and runner-up of the explanation; 4
// for reach costs: the leader, 2 companions and the next one): the award and its reason are
// the same as with every bid priced; the unpriced bids say so (Bid::priced).
// Lowest B wins; ties go to the earlier robot in FleetState order.
//
// Formation orders (§2.2): the lowest bidder leads; then every other robot's cost to reach the
// first pick is B' = alpha T_t' + beta T_d' + zeta F' with T_d' = queue travel + leg to the
// first pick, T_w' = the queue's work time (the formation's own work is not yet done there),
// F' over the leg's samples and the first pick on arrival; the two lowest B' join (ties by
// robot order). Robots that cannot reach the first pick bid +infinity and never win.
//
// Not thread-safe (scratch buffers are reused between calls to avoid per-robot allocation).
#pragma once

#include <array>
#include <limits>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include "engine/allocation/allocator.h"
#include "engine/allocation/route_sampler.h"
#include "engine/allocation/traffic_prediction.h"

namespace dispatch::engine {

class AuctionAllocator final : public Allocator {
 public:
  std::string_view name() const override { return "auction"; }
  Result<AwardExplanation> Allocate(const Order& order, FleetState& state) override;

  // Every robot's bid for `task` appended to its queue, in robot order; commits nothing.
  // keep = 0 prices every bid; keep = k > 0 only those that can be among the k lowest (the
  // others get priced = false and their lower bound). formation: the task is a formation's
  // (a robot's room in its queue is FleetState::HasRoom's for formations).
  std::vector<Bid> ComputeBids(const FleetState& state, const PlanTask& task,
                               std::size_t keep = 0, bool formation = false);
  // Every robot's cost to reach `first_pick` after its queue, in robot order; commits nothing.
  // keep as for ComputeBids.
  std::vector<Bid> ComputeReachBids(const FleetState& state, PointId first_pick,
                                    std::size_t keep = 0);

  // True when the table's costs are the sampler's travel times: a lazy table, plain or weighted
  // (exactly: double sums, from the destination outward as RouteSampler::TimeToTarget adds
  // them), or hub labels (up to rounding); no turn penalty, the allocation's speed.
  static bool CostsAreSampledTimes(const RouteTable& routes, double speed);

 private:
  // Feeds the samples of the leg from -> to (leaving at `depart`: RouteSampler::AppendLeg's
  // samples) to `density`; returns the arrival time (+infinity if unreachable). A sample on
  // an arc lying in one zone takes it without a grid lookup (ArcZone = ZoneAt there).
  double AddLegSamples(RouteSampler& sampler, const TrafficPredictor& predictor, PointId from,
                       PointId to, double depart, TrafficPredictor::DensityAccumulator& density);
  // ZoneAt(xa + f (xb - xa)) on arc `arc` (from xa to xb), remembering the last two f per arc.
  ZoneId MixedArcZone(const TrafficPredictor& predictor, ArcId arc, const Eigen::Vector2d& xa,
                      const Eigen::Vector2d& xb, double f);
  // Forgets the remembered zones (they hold for one map and one predictor: one call).
  void ResetMixedArcs(const WarehouseMap& map);
  // The sampler for one call on `state` (kept between calls for its memo's storage).
  RouteSampler& Sampler(const FleetState& state);

  // Calls price(i) for the robots that can be among the `keep` lowest bids (all when keep is
  // 0), in increasing order of their lower bounds, and marks the others unpriced. bids holds
  // every robot's time terms on entry (bid = alpha T_t + beta T_d, its bound with F = 0);
  // bound(i) returns a lower bound of robot i's F (keep > 0 only, called only for robots whose
  // time bound could still win), so alpha T_t + beta T_d + zeta bound(i) bounds its bid;
  // price(i) completes bids[i]. An unpriced bid keeps its bound: flow = bound(i) (0 when not
  // called), x and bid to match.
  template <typename Bound, typename Price>
  void PriceLowest(const AllocationConfig& c, std::vector<Bid>& bids, std::size_t keep,
                   Bound&& bound, Price&& price);

  std::optional<RouteSampler> sampler_;
  // Consecutive samples of a route in one zone, their times at [begin, begin + size) of
  // shared_times_.
  struct ZoneRun {
    ZoneId zone = -1;
    std::size_t begin = 0;
    std::size_t size = 0;
  };
  // The zones of the runs a flow bound samples, distinct and ascending (the order eqs. (7)-(8)
  // are summed in), and each run's zone's place among them: the same for every bidder of an
  // order, so indexed once per order (IndexZones).
  struct RunZones {
    std::vector<ZoneId> zones;      // the runs' zones >= 0, distinct, ascending
    std::vector<std::size_t> slot;  // per run: its zone's index in `zones` (zone < 0: unused)
  };
  static void IndexZones(const ZoneRun* runs, std::size_t run_count, RunZones& out);
  // A lower bound of robot `robot`'s F over samples of its leg to `first` and of the runs
  // (their times in `times`, from t = 0 at the first pick; `zones` indexed from them) shifted to
  // its arrival (see FlowBound in the .cpp).
  // `to_go`: the robot's time to `first` when known (< 0: the sampler walks its route).
  double FlowBound(const FleetState& state, std::size_t robot, PointId first,
                   RouteSampler& sampler, TrafficPredictor::DensityAccumulator& density,
                   const ZoneRun* runs, std::size_t run_count, const RunZones& zones, const double* times,
                   double to_go = -1.0);

  std::vector<std::pair<double, std::size_t>> order_;  // PriceLowest's heap of (bound, robot)
  std::vector<double> flow_bounds_;  // PriceLowest's bound(i) per robot (0 until taken)
  std::vector<bool> bounded_;        // PriceLowest: bound(i) taken
  std::vector<double> kept_;        // PriceLowest's k lowest full bids, ascending
  std::vector<double> legs_;        // ComputeBids, ComputeReachBids: per robot its time to the first pick (< 0: unknown)

  struct MixedSample {
    double f = std::numeric_limits<double>::quiet_NaN();  // NaN: empty (never equal)
    ZoneId zone = -1;
  };
  std::vector<std::array<MixedSample, 2>> mixed_;  // per arc id
  std::vector<ArcId> mixed_touched_;               // arcs with a remembered zone
  std::vector<RouteSample> shared_;   // the order's samples from its first pick, from t = 0
  // shared_ as runs of consecutive samples in one zone (ZoneAt), over shared_times_.
  std::vector<ZoneRun> shared_runs_;
  std::vector<double> shared_times_;  // shared_[k].t
  RunZones run_zones_;                // the zones of the runs FlowBound samples (this order's)
  std::vector<int> bound_peaks_;      // FlowBound: per zone of run_zones_, N_p,max so far
};

}  // namespace dispatch::engine
