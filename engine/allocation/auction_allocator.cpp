#include "engine/allocation/auction_allocator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <utility>

#include "engine/allocation/route_sampler.h"
#include "engine/common/numbers.h"

namespace dispatch::engine {
namespace {

Bid UnreachableBid(const std::string& robot, double ready_time) {
  Bid b;
  b.robot = robot;
  b.reachable = false;
  b.t_d = b.t_w = b.t_t = b.bid = kInf;
  b.ready_time = ready_time;
  return b;
}

Bid FullQueueBid(const std::string& robot, double ready_time) {
  Bid b = UnreachableBid(robot, ready_time);
  b.queue_full = true;
  return b;
}

void FillBid(const AllocationConfig& c, const DensityTerm& density, Bid& b) {
  b.t_t = b.t_d + b.t_w;                      // Chu2024 eq. (2)
  b.flow = density.flow;                      // Chu2024 eqs. (6)-(8)
  b.peaks = density.peaks;
  b.x = c.zeta * b.flow;                      // Chu2024 eq. (5)
  b.bid = BidValue(c.alpha, c.beta, b.t_t, b.t_d, b.x);  // Chu2024 eq. (4)
}

// Indices of the `k` lowest reachable bids (ties: robot order), skipping `skip`.
std::vector<std::size_t> Lowest(const std::vector<Bid>& bids, std::size_t k,
                                std::size_t skip = static_cast<std::size_t>(-1)) {
  std::vector<std::size_t> best;
  for (std::size_t i = 0; i < bids.size(); ++i) {
    if (i == skip || !bids[i].reachable) continue;
    std::size_t pos = best.size();
    while (pos > 0 && bids[i].bid < bids[best[pos - 1]].bid) --pos;
    if (pos < k) {
      best.insert(best.begin() + static_cast<std::ptrdiff_t>(pos), i);
      if (best.size() > k) best.pop_back();
    }
  }
  return best;
}

std::string Money(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.2f", v);
  return buf;
}

// "R5: lowest bid 69.50 (next R3 71.20)".
std::string WhyLowest(const std::vector<Bid>& bids, std::size_t winner, const char* what,
                      const std::vector<std::size_t>& excluded) {
  std::string s = bids[winner].robot + ": lowest " + what + " " + Money(bids[winner].bid);
  std::size_t next = bids.size();
  for (std::size_t i = 0; i < bids.size(); ++i) {
    bool skip = i == winner || !bids[i].reachable;
    for (std::size_t e : excluded) skip = skip || i == e;
    if (!skip && (next == bids.size() || bids[i].bid < bids[next].bid)) next = i;
  }
  if (next == bids.size()) return s + " (no other bidder)";
  if (bids[next].bid == bids[winner].bid) {
    return s + " (tied with " + bids[next].robot + "; earlier in robot order)";
  }
  return s + " (next " + bids[next].robot + " " + Money(bids[next].bid) + ")";
}

// The time terms of a reachable bid and its lower bound alpha T_t + beta T_d (x = 0).
void SetTimes(const AllocationConfig& c, double t_d, double t_w, Bid& b) {
  b.t_d = t_d;
  b.t_w = t_w;
  b.t_t = t_d + t_w;
  b.bid = BidValue(c.alpha, c.beta, b.t_t, b.t_d, 0.0);
}

// How many lowest bids an award must know exactly: 0 (all) for small fleets.
std::size_t Keep(const FleetState& state, std::size_t k) {
  return state.robot_count() <= state.config().price_every_bid_up_to ? 0 : k;
}

}  // namespace

template <typename Bound, typename Price>
void AuctionAllocator::PriceLowest(const AllocationConfig& c, std::vector<Bid>& bids,
                                   std::size_t keep, Bound&& bound, Price&& price) {
  if (keep == 0) {
    for (std::size_t i = 0; i < bids.size(); ++i) {
      if (bids[i].reachable) price(i);
    }
    return;
  }
  // A min-heap of (lower bound, robot), in two rounds per robot: first its time terms alone
  // (x = 0; F >= 0), then, when that comes out on top, alpha T_t + beta T_d + zeta bound(i).
  // Robots come out in increasing bound, ties in robot order; only those whose time bound
  // comes out pay for bound(i), and only as many as get priced pay for more.
  order_.clear();
  flow_bounds_.assign(bids.size(), 0.0);
  bounded_.assign(bids.size(), false);
  for (std::size_t i = 0; i < bids.size(); ++i) {
    if (bids[i].reachable) order_.emplace_back(bids[i].bid, i);  // SetTimes: the x = 0 bid
  }
  const auto later = std::greater<std::pair<double, std::size_t>>();
  std::make_heap(order_.begin(), order_.end(), later);
  kept_.clear();
  while (!order_.empty()) {
    const auto [key, i] = order_.front();
    // Full bids are >= their bounds: once a bound passes the keep-th lowest full bid, this
    // robot and every later one are out of the lowest `keep` (ties still priced).
    if (kept_.size() == keep && key > kept_.back()) break;
    std::pop_heap(order_.begin(), order_.end(), later);
    order_.pop_back();
    Bid& b = bids[i];
    if (!bounded_[i]) {
      bounded_[i] = true;
      flow_bounds_[i] = bound(i);
      b.bid = BidValue(c.alpha, c.beta, b.t_t, b.t_d, c.zeta * flow_bounds_[i]);
      order_.emplace_back(b.bid, i);
      std::push_heap(order_.begin(), order_.end(), later);
      continue;
    }
    price(i);
    if (!b.reachable) continue;
    kept_.insert(std::upper_bound(kept_.begin(), kept_.end(), b.bid), b.bid);
    if (kept_.size() > keep) kept_.pop_back();
  }
  for (const auto& [bound_bid, i] : order_) {
    Bid& b = bids[i];
    b.priced = false;
    b.flow = flow_bounds_[i];  // 0 when only the time bound was taken
    b.x = c.zeta * b.flow;     // b.bid is already BidValue(..., b.x)
  }
}

void AuctionAllocator::IndexZones(const ZoneRun* runs, std::size_t count, RunZones& out) {
  out.zones.clear();
  for (std::size_t r = 0; r < count; ++r) {
    if (runs[r].zone >= 0) out.zones.push_back(runs[r].zone);
  }
  std::sort(out.zones.begin(), out.zones.end());
  out.zones.erase(std::unique(out.zones.begin(), out.zones.end()), out.zones.end());
  out.slot.assign(count, 0);
  for (std::size_t r = 0; r < count; ++r) {
    if (runs[r].zone < 0) continue;
    out.slot[r] = static_cast<std::size_t>(
        std::lower_bound(out.zones.begin(), out.zones.end(), runs[r].zone) - out.zones.begin());
  }
}

double AuctionAllocator::FlowBound(const FleetState& state, std::size_t robot, PointId first,
                                   RouteSampler& sampler,
                                   TrafficPredictor::DensityAccumulator& density,
                                   const ZoneRun* runs, std::size_t run_count, const RunZones& zones,
                                   const double* times, double known_to_go) {
  const QueueSummary& s = state.summary(robot);
  const TrafficPredictor& predictor = state.predictor();
  const double to_go = known_to_go >= 0.0 ? known_to_go : sampler.TimeToTarget(s.end_point, first);
  if (!std::isfinite(to_go)) return 0.0;  // priced in time order, found unreachable there
  density.Reset(state.prediction(robot));
  // The leg's first sample exactly: its start point when it leaves (AddLegSamples' first).
  ZoneId start_zone = -1;
  int start_n = 0;
  if (s.end_point != first) {
    start_zone = predictor.ZoneAt(state.map().point(s.end_point).position);
    if (start_zone >= 0) start_n = density.Count(start_zone, s.end_time);
  }
  // The first sample of every zone run of the order's route and every kBoundStride-th after
  // it (8 m apart at h = 0.5 m: fewer samples made the bound cheaper than the few extra bids
  // it lets through cost; allocation_bench). The arrival is the leg's own up to rounding (far
  // below the slack), so each sample's bucket is in the window (DensityAccumulator::Fewest).
  // Eq. (6)'s peaks go into one slot per zone of the runs (IndexZones, once per order).
  constexpr std::size_t kBoundStride = 16;
  constexpr int kUnsampled = std::numeric_limits<int>::min();
  const double arrival = s.end_time + to_go;
  bound_peaks_.assign(zones.zones.size(), kUnsampled);
  for (std::size_t r = 0; r < run_count; ++r) {
    const ZoneRun& run = runs[r];
    if (run.zone < 0) continue;
    int& peak = bound_peaks_[zones.slot[r]];
    for (std::size_t k = 0; k < run.size; k += kBoundStride) {
      const double t = times[run.begin + k] + arrival;
      peak = std::max(peak, density.Fewest(run.zone, t, 1e-6 * std::max(1.0, std::abs(t))));
    }
  }
  // Eqs. (7)-(8) over these samples, summed in ascending zone id as DensityAccumulator::Flow
  // sums a route's: the route's F is at least this sum, rounding included.
  double flow = 0.0;
  bool start_summed = start_zone < 0;
  for (std::size_t k = 0; k < zones.zones.size(); ++k) {
    const ZoneId z = zones.zones[k];
    int peak = bound_peaks_[k];
    if (!start_summed && start_zone <= z) {
      start_summed = true;
      if (start_zone == z) {
        peak = std::max(peak, start_n);
      } else {
        flow += start_n / predictor.ZoneArea(start_zone);
      }
    }
    if (peak != kUnsampled) flow += peak / predictor.ZoneArea(z);
  }
  if (!start_summed) flow += start_n / predictor.ZoneArea(start_zone);
  return flow;
}

bool AuctionAllocator::CostsAreSampledTimes(const RouteTable& routes, double speed) {
  const RouteTableBuildInfo info = routes.build_info();
  // A weighted table (routing = heat) costs the route its NextHop follows at the same arc
  // times: the sampler's times too. Hub labels sum the same arc times in another order: equal
  // up to rounding, far below the slack FlowBound's density lookups allow.
  return (info.method == "lazy" || info.method == "weighted" || info.method == "hub_labels") &&
         !info.turn_expanded && info.speed == speed;
}

RouteSampler& AuctionAllocator::Sampler(const FleetState& state) {
  const AllocationConfig& c = state.config();
  if (!sampler_) {
    sampler_.emplace(state.map(), state.routes(), c.speed, c.sample_step);
  } else {
    sampler_->Bind(state.map(), state.routes(), c.speed, c.sample_step);
  }
  return *sampler_;
}

ZoneId AuctionAllocator::MixedArcZone(const TrafficPredictor& predictor, ArcId arc,
                                      const Eigen::Vector2d& xa, const Eigen::Vector2d& xb,
                                      double f) {
  // The same arc and the same f give the same point, so the same zone: legs towards one pick
  // cross an arc at few offsets.
  std::array<MixedSample, 2>& seen = mixed_[static_cast<std::size_t>(arc)];
  if (seen[0].f == f) return seen[0].zone;
  if (seen[1].f == f) return seen[1].zone;
  if (std::isnan(seen[0].f)) mixed_touched_.push_back(arc);
  const ZoneId zone = predictor.ZoneAt(xa + f * (xb - xa));
  seen[1] = seen[0];
  seen[0] = {f, zone};
  return zone;
}

void AuctionAllocator::ResetMixedArcs(const WarehouseMap& map) {
  for (ArcId a : mixed_touched_) mixed_[static_cast<std::size_t>(a)] = {};
  mixed_touched_.clear();
  if (mixed_.size() != map.arcs().size()) mixed_.assign(map.arcs().size(), {});
}

double AuctionAllocator::AddLegSamples(RouteSampler& sampler, const TrafficPredictor& predictor,
                                       PointId from, PointId to, double depart,
                                       TrafficPredictor::DensityAccumulator& density) {
  ArcId last_arc = -1;
  ZoneId arc_zone = TrafficPredictor::kMixedZone;
  return sampler.ForEachLegSample(
      from, to, depart,
      [&](ArcId arc, const Eigen::Vector2d& xa, const Eigen::Vector2d& xb, double f, double t) {
        if (arc != last_arc) {
          last_arc = arc;
          arc_zone = predictor.ArcZone(arc);
        }
        density.Add(arc_zone != TrafficPredictor::kMixedZone
                        ? arc_zone
                        : MixedArcZone(predictor, arc, xa, xb, f),
                    t);
      });
}

std::vector<Bid> AuctionAllocator::ComputeBids(const FleetState& state, const PlanTask& task,
                                               std::size_t keep, bool formation) {
  const AllocationConfig& c = state.config();
  const RouteTable& routes = state.routes();
  RouteSampler& sampler = Sampler(state);
  ResetMixedArcs(state.map());
  shared_.clear();
  sampler.AppendTask(task, 0.0, shared_);
  // The order's own route is the same for every bidder, only shifted in time: its zones are
  // looked up once.
  const TrafficPredictor& predictor = state.predictor();
  // They are kept as runs of consecutive samples in one zone, with the times side by side.
  shared_times_.clear();
  shared_runs_.clear();
  for (const RouteSample& r : shared_) {
    const ZoneId zone = predictor.ZoneAt(r.xy);
    if (shared_runs_.empty() || shared_runs_.back().zone != zone) {
      shared_runs_.push_back({zone, shared_times_.size(), 0});
    }
    ++shared_runs_.back().size;
    shared_times_.push_back(r.t);
  }
  IndexZones(shared_runs_.data(), shared_runs_.size(), run_zones_);
  const double task_travel = state.TaskTravelTime(task);
  const double task_work = TaskWorkTime(task);
  const PointId first = task.picks.front();
  std::vector<Bid> bids;
  bids.reserve(state.robot_count());
  // The flow bound needs each robot's time to the first pick: its leg's cost when the table's
  // costs are the sampler's times (then the same value), else the sampler's walk.
  const bool legs_are_times = CostsAreSampledTimes(routes, c.speed);
  legs_.assign(state.robot_count(), -1.0);
  for (std::size_t i = 0; i < state.robot_count(); ++i) {
    const QueueSummary& s = state.summary(i);
    if (!state.HasRoom(i, formation)) {
      bids.push_back(FullQueueBid(state.robot_id(i), s.end_time));
      continue;
    }
    if (!state.CanServe(i, task)) {  // cannot be planned into a stop's heading
      bids.push_back(UnreachableBid(state.robot_id(i), s.end_time));
      continue;
    }
    const double leg = routes.Cost(s.end_point, first);
    if (legs_are_times && std::isfinite(leg)) legs_[i] = leg;
    if (!std::isfinite(leg) || !std::isfinite(task_travel)) {
      bids.push_back(UnreachableBid(state.robot_id(i), s.end_time));
      continue;
    }
    // A four-wheel-steer robot's plan through free space is not its lanes' (issue 17 §3).
    const double refined = state.RefinedExtra(i, task);
    if (!std::isfinite(refined)) {  // the heading asked for cannot be planned for it
      bids.push_back(UnreachableBid(state.robot_id(i), s.end_time));
      continue;
    }
    Bid b;
    b.robot = state.robot_id(i);
    b.ready_time = s.end_time;
    // Chu2024 eq. (3): T_d = S_d / v and T_w = n_c * t_w over the queue and the order.
    SetTimes(c, s.travel_time + leg + task_travel + refined, s.work_time + task_work, b);
    bids.push_back(std::move(b));
  }
  TrafficPredictor::DensityAccumulator density(predictor, TrafficPredictor::PlanHandle{});
  // The lower bound of F: the leg's first sample and some of the order's own route.
  auto bound = [&](std::size_t i) {
    return FlowBound(state, i, first, sampler, density, shared_runs_.data(), shared_runs_.size(), run_zones_,
                     shared_times_.data(), legs_[i]);
  };
  PriceLowest(c, bids, keep, bound, [&](std::size_t i) {
    const QueueSummary& s = state.summary(i);
    // The leg's samples go straight into the density (a sample's order does not change
    // eqs. (6)-(8)); if the robot cannot reach the pick, they are discarded with it.
    density.Reset(state.prediction(i));
    const double arrival = AddLegSamples(sampler, predictor, s.end_point, first, s.end_time,
                                         density);
    if (!std::isfinite(arrival)) {
      bids[i] = UnreachableBid(state.robot_id(i), s.end_time);
      return;
    }
    for (const ZoneRun& run : shared_runs_) {
      density.AddRun(run.zone, shared_times_.data() + run.begin, run.size, arrival);
    }
    FillBid(c, density.Finish(), bids[i]);
  });
  return bids;
}

std::vector<Bid> AuctionAllocator::ComputeReachBids(const FleetState& state, PointId first_pick,
                                                    std::size_t keep) {
  const AllocationConfig& c = state.config();
  const RouteTable& routes = state.routes();
  RouteSampler& sampler = Sampler(state);
  ResetMixedArcs(state.map());
  const TrafficPredictor& predictor = state.predictor();
  const ZoneId pick_zone = predictor.ZoneAt(state.map().point(first_pick).position);
  std::vector<Bid> bids;
  bids.reserve(state.robot_count());
  const bool legs_are_times = CostsAreSampledTimes(routes, c.speed);  // as in ComputeBids
  legs_.assign(state.robot_count(), -1.0);
  for (std::size_t i = 0; i < state.robot_count(); ++i) {
    const QueueSummary& s = state.summary(i);
    if (!state.HasRoom(i, true)) {
      bids.push_back(FullQueueBid(state.robot_id(i), s.end_time));
      continue;
    }
    const double leg = routes.Cost(s.end_point, first_pick);
    if (legs_are_times && std::isfinite(leg)) legs_[i] = leg;
    if (!std::isfinite(leg)) {
      bids.push_back(UnreachableBid(state.robot_id(i), s.end_time));
      continue;
    }
    Bid b;
    b.robot = state.robot_id(i);
    b.ready_time = s.end_time;
    SetTimes(c, s.travel_time + leg, s.work_time, b);
    bids.push_back(std::move(b));
  }
  TrafficPredictor::DensityAccumulator density(predictor, TrafficPredictor::PlanHandle{});
  // The lower bound of F': the leg's first sample and the first pick on arrival.
  const ZoneRun pick_run{pick_zone, 0, 1};
  const double on_arrival = 0.0;
  IndexZones(&pick_run, 1, run_zones_);
  auto bound = [&](std::size_t i) {
    return FlowBound(state, i, first_pick, sampler, density, &pick_run, 1, run_zones_, &on_arrival, legs_[i]);
  };
  PriceLowest(c, bids, keep, bound, [&](std::size_t i) {
    const QueueSummary& s = state.summary(i);
    density.Reset(state.prediction(i));
    const double arrival = AddLegSamples(sampler, predictor, s.end_point, first_pick,
                                         s.end_time, density);
    if (!std::isfinite(arrival)) {
      bids[i] = UnreachableBid(state.robot_id(i), s.end_time);
      return;
    }
    density.Add(pick_zone, arrival);  // the first pick on arrival
    FillBid(c, density.Finish(), bids[i]);
  });
  return bids;
}

Result<AwardExplanation> AuctionAllocator::Allocate(const Order& order, FleetState& state) {
  Result<PlanTask> task = PrepareOrder(order, state);
  if (!task.ok()) return task.error();
  const std::string first_name = "'" + state.map().point(task->picks.front()).name + "'";
  AwardExplanation ex;
  ex.order_id = order.id;
  ex.strategy = std::string(name());
  ex.bids = ComputeBids(state, *task, Keep(state, 2), order.formation);
  const std::vector<std::size_t> leader = Lowest(ex.bids, 1);
  if (leader.empty()) {
    return Unreachable("order " + order.id + ": no robot can reach the first pick " + first_name);
  }
  const std::size_t lead = leader.front();
  ex.reason = WhyLowest(ex.bids, lead, "bid", {});
  if (!order.formation) {
    if (Status s = state.AssignSingle(lead, order.id, *task); !s.ok()) return s.error();
    ex.winners = {ex.bids[lead].robot};
    return ex;
  }
  // Chu2024 §2.2: the two robots with the lowest cost to reach the first pick join.
  std::vector<Bid> reach = ComputeReachBids(state, task->picks.front(), Keep(state, 4));
  const std::vector<std::size_t> companions = Lowest(reach, 2, lead);
  if (companions.size() < 2) {
    return Unreachable("order " + order.id + ": a formation needs 2 companions for leader " +
                       ex.bids[lead].robot + ", only " + std::to_string(companions.size()) +
                       " other robot(s) can reach the first pick " + first_name);
  }
  if (Status s = state.AssignFormation({lead, companions[0], companions[1]}, order.id, *task);
      !s.ok()) {
    return s.error();
  }
  ex.winners = {ex.bids[lead].robot, reach[companions[0]].robot, reach[companions[1]].robot};
  ex.reason = "leader " + ex.reason + "; companions " + reach[companions[0]].robot + " (" +
              Money(reach[companions[0]].bid) + ") and " + reach[companions[1]].robot + " (" +
              Money(reach[companions[1]].bid) + "): lowest costs to reach the first pick " +
              first_name;
  {
    std::string next = WhyLowest(reach, companions[1], "reach cost", {lead, companions[0]});
    const std::size_t paren = next.find(" (");
    if (paren != std::string::npos) ex.reason += next.substr(paren);
  }
  for (std::size_t i = 0; i < reach.size(); ++i) {
    if (i != lead) ex.companion_bids.push_back(std::move(reach[i]));
  }
  return ex;
}

}  // namespace dispatch::engine
