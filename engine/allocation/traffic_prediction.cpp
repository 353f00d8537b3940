#include "engine/allocation/traffic_prediction.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

namespace dispatch::engine {
namespace {

// Beyond this many buckets a plan's time span is treated as a broken contract.
constexpr double kMaxBuckets = 4.0e9;

void ValidateConfig(const TrafficPredictionConfig& c) {
  if (!(c.bucket_seconds > 0.0) || !std::isfinite(c.bucket_seconds) ||
      !std::isfinite(c.origin_time) || !(c.zone_cell_size > 0.0) ||
      !std::isfinite(c.zone_cell_size)) {
    throw std::invalid_argument("TrafficPredictionConfig: bucket_seconds and zone_cell_size "
                                "must be positive and finite, origin_time finite");
  }
}

}  // namespace

TrafficPredictor::TrafficPredictor(const WarehouseMap& map, TrafficPredictionConfig config)
    : config_(config) {
  ValidateConfig(config_);
  index_ = std::make_shared<const ZoneIndex>(map, config_.zone_cell_size);
  inv_bucket_seconds_ = 1.0 / config_.bucket_seconds;
  bucket_starts_ = {BucketStart(0)};
}

TrafficPredictor::TrafficPredictor(std::shared_ptr<const ZoneIndex> index,
                                   TrafficPredictionConfig config)
    : config_(config), index_(std::move(index)) {
  ValidateConfig(config_);
  if (!index_ || index_->requested_cell_size() != config_.zone_cell_size) {
    throw std::invalid_argument("TrafficPredictor: no zone index, or one built for another "
                                "zone_cell_size");
  }
  inv_bucket_seconds_ = 1.0 / config_.bucket_seconds;
  bucket_starts_ = {BucketStart(0)};
}

// --- Buckets and counts ---------------------------------------------------------------------

void TrafficPredictor::Apply(const Contribution& c, int sign) {
  const std::size_t tail = std::min(c.tail, c.zones.size());
  for (std::size_t k = 0; k < tail; ++k) {
    if (c.zones[k] < 0) continue;
    counts_[static_cast<std::size_t>(c.zones[k]) * bucket_stride_ + c.first_bucket + k] += sign;
  }
  // The final run in one zone (a plan's last stop and hold): adjacent counts of one row.
  if (tail < c.zones.size() && c.zones.back() >= 0) {
    std::int32_t* row = counts_.data() + static_cast<std::size_t>(c.zones.back()) * bucket_stride_ + c.first_bucket;
    for (std::size_t k = tail; k < c.zones.size(); ++k) row[k] += sign;
  }
}

TrafficPredictor::PlanHandle TrafficPredictor::SetPlan(const std::string& robot,
                                                       const Plan& plan) {
  if (robot.empty()) throw std::invalid_argument("TrafficPredictor::SetPlan: empty robot id");
  if (plan.waypoints.empty()) {
    RemovePlan(robot);
    return PlanHandle{};
  }
  Contribution next = Trace(robot, plan, config_.origin_time);
  if (!next.zones.empty()) Reserve(next.first_bucket + next.zones.size());
  return Install(robot, std::move(next));
}

TrafficPredictor::PlanHandle TrafficPredictor::SetTraced(const std::string& robot, const Contribution& trace,
                                                         std::size_t offset) {
  if (robot.empty()) throw std::invalid_argument("TrafficPredictor::SetTraced: empty robot id");
  if (!trace.zones.empty()) Reserve(trace.first_bucket + offset + trace.zones.size());
  auto [it, inserted] = robots_.try_emplace(robot);
  Contribution& c = it->second;
  if (!inserted) Apply(c, -1);
  c.first_bucket = trace.first_bucket + offset;
  c.zones.assign(trace.zones.begin(), trace.zones.end());  // the robot's storage kept
  c.tail = trace.tail;
  Apply(c, +1);
  return HandleOf(c);
}

TrafficPredictor::Contribution TrafficPredictor::Trace(const std::string& robot, const Plan& plan,
                                                       double origin, double hold) const {
  Contribution next;
  if (plan.waypoints.empty()) return next;
  // A hold adds buckets at the last waypoint only: the walk below ends there (its last branch).
  const double start = plan.start_time(), end = plan.end_time() + hold;
  if (!std::isfinite(start) || !std::isfinite(end) || !std::isfinite(origin)) {
    throw std::invalid_argument("TrafficPredictor::SetPlan: non-finite plan times for " + robot);
  }
  const double dt = config_.bucket_seconds;
  // s_b of the grid from `origin`: the same expression as BucketStart.
  const auto at = [origin, dt](std::size_t b) { return origin + static_cast<double>(b) * dt; };
  if (end >= origin && start <= end) {
    // First bucket: the smallest b >= 0 with s_b >= start; last: the largest with s_b <= end.
    const double q0 = std::max(0.0, std::ceil((start - origin) / dt));
    const double q1 = std::floor((end - origin) / dt);
    if (q1 > kMaxBuckets) {
      throw std::invalid_argument("TrafficPredictor::SetPlan: plan of " + robot +
                                  " ends too far after origin_time");
    }
    std::size_t first = static_cast<std::size_t>(std::min(q0, q1 + 2.0));
    while (first > 0 && at(first - 1) >= start) --first;
    while (at(first) < start) ++first;
    std::size_t last_plus_one = static_cast<std::size_t>(std::max(q1, 0.0));
    while (last_plus_one > 0 && at(last_plus_one) > end) --last_plus_one;
    while (at(last_plus_one) <= end) ++last_plus_one;  // now one past the last
    next.first_bucket = first;
    if (last_plus_one > first) {
      next.zones.reserve(last_plus_one - first);
      // Plan::PositionAt at increasing times with a cursor (amortised O(1) per bucket instead
      // of a binary search), and ZoneAt only when the position moved (a robot standing for
      // many buckets at a pick costs one lookup). Same results as calling them directly.
      const auto& w = plan.waypoints;
      std::size_t upper = 0;  // first waypoint with eta > t
      Eigen::Vector2d last_xy(std::numeric_limits<double>::quiet_NaN(), 0.0);
      ZoneId last_zone = -1;
      for (std::size_t b = first; b < last_plus_one; ++b) {
        const double t = at(b);
        Eigen::Vector2d xy;
        if (t <= w.front().eta) {
          xy = w.front().xy;
        } else {
          while (upper < w.size() && !(t < w[upper].eta)) ++upper;
          if (upper == w.size()) {
            // At the last waypoint from here on (its dwell, then the plan's end): one zone
            // for every bucket left (a plan's final hold is hundreds of buckets).
            if (!(w.back().xy == last_xy)) last_zone = index_->ZoneAt(w.back().xy);
            next.zones.resize(last_plus_one - first, last_zone);
            break;
          }
          const Waypoint& from = w[upper - 1];
          if (t <= from.departure()) {
            xy = from.xy;
          } else {
            const Waypoint& to = w[upper];
            const double span = to.eta - from.departure();
            xy = span <= 0.0 ? to.xy : Eigen::Vector2d(from.xy + ((t - from.departure()) / span) * (to.xy - from.xy));
          }
        }
        if (!(xy == last_xy)) {
          last_zone = index_->ZoneAt(xy);
          last_xy = xy;
        }
        next.zones.push_back(last_zone);
      }
      next.tail = next.zones.size();
      while (next.tail > 0 && next.zones[next.tail - 1] == next.zones.back()) --next.tail;
    }
  }
  return next;
}

void TrafficPredictor::Reserve(std::size_t end) {
  if (end > bucket_stride_) {
    // Zone-major rows grow by doubling (amortised O(1) per bucket); the tail stays 0.
    const std::size_t stride = std::max(end, 2 * bucket_stride_);
    std::vector<std::int32_t> grown(stride * index_->zones().size(), 0);
    for (std::size_t z = 0; z < index_->zones().size(); ++z) {
      std::copy_n(counts_.begin() + static_cast<std::ptrdiff_t>(z * bucket_stride_),
                  bucket_count_, grown.begin() + static_cast<std::ptrdiff_t>(z * stride));
    }
    counts_ = std::move(grown);
    bucket_stride_ = stride;
  }
  for (std::size_t b = bucket_count_ + 1; b <= end; ++b) bucket_starts_.push_back(BucketStart(b));
  bucket_count_ = std::max(bucket_count_, end);
}

TrafficPredictor::PlanHandle TrafficPredictor::Install(const std::string& robot, Contribution next) {
  auto [it, inserted] = robots_.try_emplace(robot);
  if (!inserted) Apply(it->second, -1);
  Apply(next, +1);
  it->second = std::move(next);
  return HandleOf(it->second);  // unordered_map nodes (and their zones) stay put until erased
}

TrafficPredictor::PlanHandle TrafficPredictor::HandleOf(const Contribution& c) {
  PlanHandle h;
  if (c.zones.empty()) return h;
  h.zones_ = c.zones.data();
  h.first_ = c.first_bucket;
  h.tail_ = c.first_bucket + c.tail;
  h.end_ = c.first_bucket + c.zones.size();
  h.tail_zone_ = c.zones.back();
  return h;
}

TrafficPredictor::PlanHandle TrafficPredictor::Find(const std::string& robot) const {
  auto it = robots_.find(robot);
  return it == robots_.end() ? PlanHandle{} : HandleOf(it->second);
}

void TrafficPredictor::RemovePlan(const std::string& robot) {
  auto it = robots_.find(robot);
  if (it == robots_.end()) return;
  Apply(it->second, -1);
  robots_.erase(it);
}

int TrafficPredictor::CountAt(ZoneId zone, double t, const std::string& exclude_robot) const {
  if (zone < 0 || static_cast<std::size_t>(zone) >= index_->zones().size()) return 0;
  std::size_t b = 0;
  if (!StoredBucketOf(t, &b)) return 0;
  int n = counts_[static_cast<std::size_t>(zone) * bucket_stride_ + b];
  if (!exclude_robot.empty()) {
    auto it = robots_.find(exclude_robot);
    if (it != robots_.end() && ZoneOf(&it->second, b) == zone) --n;
  }
  return n;
}

// Chu2024 eqs. (6)-(8).
DensityTerm TrafficPredictor::Density(const std::vector<RouteSample>& samples,
                                      const std::string& robot) const {
  DensityAccumulator acc(*this, robot);
  for (const RouteSample& s : samples) acc.Add(s.xy, s.t);
  return acc.Finish();
}

TrafficPredictor::DensityAccumulator::DensityAccumulator(const TrafficPredictor& predictor,
                                                         const std::string& robot)
    : DensityAccumulator(predictor, robot.empty() ? PlanHandle{} : predictor.Find(robot)) {}

TrafficPredictor::DensityAccumulator::DensityAccumulator(const TrafficPredictor& predictor,
                                                         PlanHandle own)
    : predictor_(&predictor) {
  Reset(own);
}

void TrafficPredictor::DensityAccumulator::Reset(PlanHandle own) {
  own_zones_ = own.zones_;
  own_first_ = own.first_;
  own_tail_ = own.tail_;
  own_end_ = own.end_;
  tail_zone_ = own.tail_zone_;
  peaks_.clear();
  last_ = 0;
  cursor_ = 0;
  if (++slot_stamp_ == 0) {  // wrapped: no slot may look current
    std::fill(slot_seen_.begin(), slot_seen_.end(), 0);
    slot_stamp_ = 1;
  }
}

void TrafficPredictor::DensityAccumulator::NewZone(ZoneId zone, int n) {
  const auto z = static_cast<std::size_t>(zone);
  if (z >= slot_seen_.size()) {
    const std::size_t zones = std::max(predictor_->index_->zones().size(), z + 1);
    slot_seen_.resize(zones, 0);
    slot_.resize(zones, 0);
  }
  if (slot_seen_[z] == slot_stamp_) {
    last_ = slot_[z];
    return;
  }
  // A new zone: into its place by zone id (Flow and Finish sum in that order), the later
  // zones' slots one further.
  std::size_t at = peaks_.size();
  while (at > 0 && peaks_[at - 1].first > zone) {
    ++slot_[static_cast<std::size_t>(peaks_[at - 1].first)];
    --at;
  }
  peaks_.insert(peaks_.begin() + static_cast<std::ptrdiff_t>(at), {zone, n});
  slot_seen_[z] = slot_stamp_;
  slot_[z] = last_ = at;
}

void TrafficPredictor::DensityAccumulator::AddRun(ZoneId zone, const double* times,
                                                  std::size_t n, double shift) {
  if (zone < 0 || n == 0) return;
  const TrafficPredictor& p = *predictor_;
  const std::int32_t* row = p.counts_.data() + static_cast<std::size_t>(zone) * p.bucket_stride_;
  int peak = std::numeric_limits<int>::min();
  for (std::size_t k = 0; k < n; ++k) {
    int c = 0;
    std::size_t b = 0;
    if (Locate(times[k] + shift, &b)) {
      c = row[b];
      if (OwnZone(b) == zone) --c;
    }
    peak = std::max(peak, c);
  }
  Record(zone, peak);
}

int TrafficPredictor::DensityAccumulator::FewestFrom(const std::int32_t* row, ZoneId zone, std::size_t lo,
                                                     double t_hi) const {
  const TrafficPredictor& p = *predictor_;
  const double* starts = p.bucket_starts_.data();  // bucket_count_ + 1 entries
  // hi = bucket(t_hi): from lo up (s_b is non-decreasing in b).
  std::size_t hi = lo;
  while (hi < p.bucket_count_ && starts[hi + 1] <= t_hi) ++hi;
  if (hi >= p.bucket_count_) return 0;
  int n = std::numeric_limits<int>::max();
  for (std::size_t b = lo; b <= hi; ++b) n = std::min(n, row[b] - (OwnZone(b) == zone ? 1 : 0));
  return n;
}

double TrafficPredictor::DensityAccumulator::Flow() {
  double flow = 0.0;
  for (const auto& [z, n_max] : peaks_) {  // by zone id (NewZone)
    flow += n_max / predictor_->index_->zones()[static_cast<std::size_t>(z)].area;  // eqs. (7)-(8)
  }
  return flow;
}

DensityTerm TrafficPredictor::DensityAccumulator::Finish() const {
  DensityTerm term;
  term.peaks = peaks_;  // by zone id (NewZone)
  for (const auto& [z, n_max] : term.peaks) {
    term.flow += n_max / predictor_->index_->zones()[static_cast<std::size_t>(z)].area;  // eqs. (7)-(8)
  }
  return term;
}

// --- Route samples --------------------------------------------------------------------------

void SamplePlan(const Plan& plan, double step, std::vector<RouteSample>* out) {
  if (!(step > 0.0) || !std::isfinite(step)) {
    throw std::invalid_argument("SamplePlan: step must be positive and finite");
  }
  out->clear();
  const std::vector<Waypoint>& w = plan.waypoints;
  if (w.empty()) return;
  double total = 0.0;
  for (std::size_t i = 0; i + 1 < w.size(); ++i) total += (w[i + 1].xy - w[i].xy).norm();
  out->reserve(static_cast<std::size_t>(total / step) + 2);

  // Distances k * step (not accumulated, so no drift); a sample within kEps of a leg's end
  // lands exactly on its waypoint.
  constexpr double kEps = 1e-9;
  out->push_back({w.front().xy, w.front().eta});
  std::size_t k = 1;
  double next = step, travelled = 0.0;
  for (std::size_t i = 0; i + 1 < w.size(); ++i) {
    const Eigen::Vector2d& a = w[i].xy;
    const Eigen::Vector2d& b = w[i + 1].xy;
    const double length = (b - a).norm();
    const double t0 = w[i].departure(), t1 = w[i + 1].eta;
    const double leg_end = travelled + length;
    while (next <= leg_end + kEps) {
      const double f = length > 0.0 ? (next - travelled) / length : 1.0;
      if (f >= 1.0) {
        out->push_back({b, t1});
      } else {
        out->push_back({a + f * (b - a), t0 + f * (t1 - t0)});
      }
      ++k;
      next = static_cast<double>(k) * step;
    }
    travelled = leg_end;
  }
  const Waypoint& last = w.back();
  if (out->back().xy != last.xy || out->back().t != last.eta) out->push_back({last.xy, last.eta});
}

std::vector<RouteSample> SamplePlan(const Plan& plan, double step) {
  std::vector<RouteSample> out;
  SamplePlan(plan, step, &out);
  return out;
}

}  // namespace dispatch::engine
