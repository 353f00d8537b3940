// Traffic-flow prediction (Chu2024 §2.3, eqs. (5)-(8)): how many robots each zone is
// predicted to hold at each time, from all robots' timed plans, so that an auction bid can
// price the density along a candidate route.
//
// Buckets: bucket b covers [s_b, s_(b+1)) with s_b = origin_time + b * bucket_seconds (this
// exact expression everywhere). A plan contributes, for every bucket b with
// plan.start_time() <= s_b <= plan.end_time(), one robot in the zone holding
// plan.PositionAt(s_b) (none if that position is in no zone). Before its start and after its
// end a plan predicts nothing: an idle robot needs a plan with a park/wait dwell to be seen.
// A time t is looked up in bucket(t) = the largest b >= 0 with s_b <= t (times before
// origin_time clamp to bucket 0), so CountAt(p, t) is the count at s_bucket(t). Counts are
// kept per (bucket, zone) and per robot, so "other robots in zone p at time t" is O(1):
// count(bucket(t), p) - [robot's own zone at bucket(t) == p].
//
// Zones: ZoneAt and ArcZone come from a ZoneIndex (zone_index.h), built by the first
// constructor or shared through the second.
//
// Invariant: after SetPlan/RemovePlan the counts equal a recount from scratch over the current
// plans (a model test checks this). The predictor keeps no reference to the map. Not
// thread-safe: one writer (the allocator) at a time; const methods
// may run concurrently with each other.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "engine/allocation/zone_index.h"
#include "engine/fleet/plan.h"
#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

struct TrafficPredictionConfig {
  double bucket_seconds = 0.5;  // time resolution of the prediction (> 0)
  double origin_time = 0.0;     // time of bucket 0; earlier times clamp to bucket 0
  // Edge of the ZoneAt grid cells, metres (> 0). Raised automatically so the grid has at most
  // kMaxZoneCells cells (4 bytes each): 0.25 m keeps a 500 x 140 m LoRR floor at 1.1 M cells
  // (4.5 MB); the Chu2024 floor (39.5 x 27.5 m) needs 17 k.
  double zone_cell_size = 0.25;
  static constexpr std::size_t kMaxZoneCells = ZoneIndex::kMaxZoneCells;
};

// A point of a candidate route: where robot i would be (xy) and when (t).
struct RouteSample {
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();
  double t = 0.0;
};

// F_i with its parts, for explanations: per zone the peak N_p,max(i) (eq. 6) and
// rho_p(i) = N_p,max(i) / S_p (eq. 7); F = sum over zones (eq. 8).
struct DensityTerm {
  double flow = 0.0;                          // F_i
  std::vector<std::pair<ZoneId, int>> peaks;  // zones the route visits with N_p,max(i), by id
};

class TrafficPredictor {
 public:
  // What one robot's plan adds: zones[k] is its zone (or -1) at bucket first_bucket + k.
  struct Contribution {
    std::size_t first_bucket = 0;
    std::vector<ZoneId> zones;
    std::size_t tail = 0;  // zones[k] == zones.back() for every k >= tail (a plan's final wait)
  };
  // Density's computation fed one sample at a time, for callers that already know a sample's
  // zone (the auction reuses the zones of an order's route for every bidder). Holds pointers
  // into the predictor: use it only while the predictor is not modified.
  class DensityAccumulator;
  // A robot's stored prediction, to build a DensityAccumulator without looking the robot up
  // by id. Valid until that robot's next SetPlan or RemovePlan (use the handle SetPlan
  // returns); a default PlanHandle stands for no plan.
  class PlanHandle {
   public:
    PlanHandle() = default;

   private:
    friend class TrafficPredictor;
    friend class DensityAccumulator;
    // The contribution's shape, copied so that DensityAccumulator::Reset reads no more than
    // the handle (the contribution itself is read only for buckets before its tail).
    const ZoneId* zones_ = nullptr;  // zone at bucket first_ + k; nullptr: no plan
    std::size_t first_ = 0, tail_ = 0, end_ = 0;  // bucket ranges as in Contribution
    ZoneId tail_zone_ = -1;
  };

  // Builds its ZoneIndex (see there for the cost). Throws std::invalid_argument on a
  // non-positive or non-finite setting (broken contract).
  TrafficPredictor(const WarehouseMap& map, TrafficPredictionConfig config);
  // Shares `index` (built for config.zone_cell_size: std::invalid_argument otherwise, or for
  // a null index): O(1), for predictors rebuilt every round on one map.
  TrafficPredictor(std::shared_ptr<const ZoneIndex> index, TrafficPredictionConfig config);

  // Replaces robot `robot`'s contribution with `plan` (adds it if new); an empty plan removes
  // it. O(buckets of the old and new plan x log waypoints). Storage grows to the plan's last
  // bucket. Returns the robot's handle (a default one when `plan` is empty). Throws
  // std::invalid_argument on an empty robot id or non-finite plan times.
  PlanHandle SetPlan(const std::string& robot, const Plan& plan);
  // What SetPlan would add for `plan` followed by a wait of `hold` seconds (>= 0) at its last
  // waypoint if origin_time were `origin` (the same bucket_seconds), counting nothing: a plan
  // traced once and moved by whole buckets afterwards (SetTraced: a queue that stays the same
  // from one allocation round to the next, only later). Throws as SetPlan.
  Contribution Trace(const std::string& robot, const Plan& plan, double origin, double hold = 0.0) const;
  // Replaces robot `robot`'s contribution with `trace` moved `offset` buckets later (bucket
  // trace.first_bucket + offset + k holds trace.zones[k]): with trace = Trace(plan, origin),
  // what SetPlan adds for the plan moved offset * bucket_seconds later when origin_time is
  // `origin`, up to rounding at bucket starts. O(buckets of the old and new contribution).
  PlanHandle SetTraced(const std::string& robot, const Contribution& trace, std::size_t offset);
  // Removes robot `robot`'s contribution; unknown robots are ignored.
  void RemovePlan(const std::string& robot);
  // The handle of robot `robot`'s current plan (a default one if it has none): one hash
  // lookup.
  PlanHandle Find(const std::string& robot) const;

  // The zone holding xy: ZoneIndex::ZoneAt.
  ZoneId ZoneAt(const Eigen::Vector2d& xy) const { return index_->ZoneAt(xy); }
  static constexpr ZoneId kMixedZone = ZoneIndex::kMixedZone;
  // ZoneIndex::ArcZone.
  ZoneId ArcZone(ArcId arc) const { return index_->ArcZone(arc); }
  const std::shared_ptr<const ZoneIndex>& zone_index() const { return index_; }
  // S_p of zone p (>= 0): the area Chu2024 eq. (7) divides by.
  double ZoneArea(ZoneId zone) const { return index_->zones()[static_cast<std::size_t>(zone)].area; }
  // Robots predicted in `zone` at time t (see the bucket rule above), not counting
  // `exclude_robot` (may be empty). 0 for an unknown zone, a NaN time or a time past the
  // last stored bucket. O(1) (one hash lookup when `exclude_robot` is given).
  int CountAt(ZoneId zone, double t, const std::string& exclude_robot = {}) const;
  // Chu2024 eqs. (6)-(8) over the samples of robot `robot`'s candidate route (taken every h
  // metres by the caller, e.g. SamplePlan): for each sample the zone ZoneAt(xy) and the count
  // of other robots CountAt(zone, t, robot); N_p,max = the peak over the samples in zone p
  // (eq. 6); F = sum_p N_p,max / S_p (eqs. 7-8). Samples in no zone are skipped; zones the
  // route never visits are not in `peaks`. O(samples x zones visited).
  DensityTerm Density(const std::vector<RouteSample>& samples, const std::string& robot) const;


  // Buckets with storage: one past the last bucket any plan has reached (never shrinks).
  std::size_t bucket_count() const { return bucket_count_; }
  std::size_t robot_count() const { return robots_.size(); }
  const TrafficPredictionConfig& config() const { return config_; }
  // The grid actually used (after the kMaxZoneCells cap).
  double zone_cell_size() const { return index_->cell_size(); }

 private:
  double BucketStart(std::size_t b) const {
    return config_.origin_time + static_cast<double>(b) * config_.bucket_seconds;
  }
  // Grows the counts' storage (and bucket_starts_) to hold buckets [0, end).
  void Reserve(std::size_t end);
  // Installs `next` as robot's contribution (storage reserved).
  PlanHandle Install(const std::string& robot, Contribution next);
  // bucket(t) as above; false for NaN or a bucket >= bucket_count_. Inline: the hot path.
  bool StoredBucketOf(double t, std::size_t* bucket) const {
    // A multiply and a truncation, no libm call.
    const double q = (t - config_.origin_time) * inv_bucket_seconds_;
    if (!(q < static_cast<double>(bucket_count_) + 1.0)) return false;  // also NaN
    std::size_t b = q > 0.0 ? static_cast<std::size_t>(q) : 0;  // floor for q >= 0, <= count
    // Snap to the exact rule (largest b with s_b <= t) against rounding of the product, with
    // s_b read from bucket_starts_ (b <= bucket_count_ here). b only grows in the second
    // loop, so once it reaches bucket_count_ the answer is "not stored".
    const double* starts = bucket_starts_.data();
    while (b > 0 && starts[b] > t) --b;
    for (;;) {
      if (b >= bucket_count_) return false;
      if (starts[b + 1] > t) break;
      ++b;
    }
    *bucket = b;
    return true;
  }
  void Apply(const Contribution& c, int sign);
  static PlanHandle HandleOf(const Contribution& c);
  static ZoneId ZoneOf(const Contribution* c, std::size_t bucket) {
    if (c == nullptr || bucket < c->first_bucket || bucket - c->first_bucket >= c->zones.size()) {
      return -1;
    }
    return c->zones[bucket - c->first_bucket];
  }

  TrafficPredictionConfig config_;
  double inv_bucket_seconds_ = 2.0;  // 1 / bucket_seconds
  std::shared_ptr<const ZoneIndex> index_;

  // counts_[p * bucket_stride_ + b]: robots in zone p at s_b, over all robots' plans (zone
  // major, so the consecutive buckets a route spends in one zone are adjacent); buckets in
  // [bucket_count_, bucket_stride_) are 0.
  std::size_t bucket_count_ = 0;
  std::size_t bucket_stride_ = 0;
  std::vector<double> bucket_starts_ = {0.0};  // BucketStart(b) for b <= bucket_count_
  std::vector<std::int32_t> counts_;
  std::unordered_map<std::string, Contribution> robots_;
};

class TrafficPredictor::DensityAccumulator {
 public:
  // Counts exclude robot `robot`'s own plan (none when empty or unknown).
  DensityAccumulator(const TrafficPredictor& predictor, const std::string& robot);
  // Counts exclude the plan behind `own` (none for a default handle).
  DensityAccumulator(const TrafficPredictor& predictor, PlanHandle own);
  // Starts over for another robot, keeping the buffers (no allocation once warm).
  void Reset(PlanHandle own);
  // A sample in `zone` (skipped when < 0) at time t. Inline: every route sample comes here.
  void Add(ZoneId zone, double t) {
    if (zone >= 0) Record(zone, Count(zone, t));
  }
  // What Add records for a sample in `zone` (>= 0) at time t, without recording it:
  // N_p^k(i), the other robots in a_p when robot i is at sample k.
  int Count(ZoneId zone, double t) {
    std::size_t b = 0;
    if (!Locate(t, &b)) return 0;
    const int n = predictor_->counts_[static_cast<std::size_t>(zone) * predictor_->bucket_stride_ + b];
    return OwnZone(b) == zone ? n - 1 : n;
  }
  void Add(const Eigen::Vector2d& xy, double t) { Add(predictor_->ZoneAt(xy), t); }
  // n samples in `zone` (none when < 0) at times times[k] + shift: the same as
  // Add(zone, times[k] + shift) for each k, in one tight loop.
  void AddRun(ZoneId zone, const double* times, std::size_t n, double shift);
  // A sample in `zone` (skipped when < 0) at a time known only to lie within `slack` of t:
  // counts the fewest other robots of the buckets [bucket(t - slack), bucket(t + slack)] (0 for
  // unstored ones), so the peaks stay at or below those of the exact time. For lower bounds
  // of F; O(buckets in the window).
  void AddAtMost(ZoneId zone, double t, double slack) {
    if (zone >= 0) Record(zone, Fewest(zone, t, slack));
  }
  // What AddAtMost records for a sample in `zone` (>= 0), without recording it: the fewest
  // other robots over the window's buckets. O(buckets in the window); no cursor walk (for
  // samples far apart). Inline: a window mostly holds one bucket.
  int Fewest(ZoneId zone, double t, double slack) const {
    const TrafficPredictor& p = *predictor_;
    std::size_t lo = 0;
    // An unstored bucket in the window (or a NaN time): no robot there.
    if (!p.StoredBucketOf(t - slack, &lo)) return 0;
    const std::int32_t* row = p.counts_.data() + static_cast<std::size_t>(zone) * p.bucket_stride_;
    // lo < bucket_count_: bucket_starts_ holds s_(lo + 1). A window of one bucket, or of two
    // (a sample time on a bucket start: route times on a 1 m grid at 1 m/s often are).
    const double* starts = p.bucket_starts_.data();
    const double t_hi = t + slack;
    const int at_lo = row[lo] - (OwnZone(lo) == zone ? 1 : 0);
    if (starts[lo + 1] > t_hi) return at_lo;
    if (lo + 1 < p.bucket_count_ && starts[lo + 2] > t_hi) {
      return std::min(at_lo, row[lo + 1] - (OwnZone(lo + 1) == zone ? 1 : 0));
    }
    return FewestFrom(row, zone, lo, t_hi);
  }
  // Eqs. (6)-(8) over the samples added so far; peaks sorted by zone id.
  DensityTerm Finish() const;
  // Finish().flow without building the term (summed in the same zone order, so a route's F
  // is at least the Flow of any subset of its samples, rounding included). No allocation once
  // warm.
  double Flow();

 private:
  const TrafficPredictor* predictor_;
  // The own plan as bucket ranges: its zone at b in [own_first_, own_end_) is own_zones_[b -
  // own_first_], which is tail_zone_ from own_tail_ on (no memory access on the hot path).
  std::size_t own_first_ = 0, own_tail_ = 0, own_end_ = 0;
  const ZoneId* own_zones_ = nullptr;
  ZoneId tail_zone_ = -1;
  std::vector<std::pair<ZoneId, int>> peaks_;  // N_p,max so far, by zone id
  std::size_t last_ = 0;                       // index of the last zone added
  // peaks_'s entry of each zone: slot_[z], valid when slot_seen_[z] == slot_stamp_ (Reset
  // moves the stamp on instead of clearing them).
  std::vector<std::size_t> slot_;
  std::vector<std::uint32_t> slot_seen_;
  std::uint32_t slot_stamp_ = 0;

  std::size_t cursor_ = 0;  // the bucket of the last sample located (or 0)

  // The own plan's zone at bucket b (-1 if none).
  ZoneId OwnZone(std::size_t b) const {
    if (b >= own_end_) return -1;
    if (b >= own_tail_) return tail_zone_;
    return b >= own_first_ ? own_zones_[b - own_first_] : -1;
  }

  // Eq. (6): N_p,max(i) = max over the samples in zone p. A route visits few zones and
  // consecutive samples mostly share one: a short list with a last-zone shortcut.
  void Record(ZoneId zone, int n) {
    if (last_ >= peaks_.size() || peaks_[last_].first != zone) NewZone(zone, n);
    peaks_[last_].second = std::max(peaks_[last_].second, n);
  }
  // Points last_ at zone's entry, appending (zone, n) if the zone is new.
  void NewZone(ZoneId zone, int n);
  // Fewest over the buckets [lo, bucket(t_hi)] of `row` (zone's counts), 0 if one is unstored.
  int FewestFrom(const std::int32_t* row, ZoneId zone, std::size_t lo, double t_hi) const;
  // StoredBucketOf(t), walking from the last sample's bucket when t is at most kWalk buckets
  // past it (a route's samples come in time order, one to a few buckets apart). bucket(t) is
  // the largest b with s_b <= t and s_b is non-decreasing in b, so s_c <= t < s_(c+1) pins
  // bucket(t) = c whichever way c was found.
  static constexpr int kWalk = 8;
  bool Locate(double t, std::size_t* bucket) {
    const TrafficPredictor& p = *predictor_;
    const std::size_t count = p.bucket_count_;
    const double* starts = p.bucket_starts_.data();  // count + 1 entries
    std::size_t b = cursor_;
    if (t >= starts[b]) {  // false for NaN
      for (int k = 0; k < kWalk && b < count && starts[b + 1] <= t; ++k) ++b;
      if (!(b < count && starts[b + 1] <= t)) {
        cursor_ = b;
        if (b >= count) return false;  // bucket(t) >= count: not stored
        *bucket = b;
        return true;
      }
    }
    if (!p.StoredBucketOf(t, bucket)) return false;
    cursor_ = *bucket;
    return true;
  }
};

// Samples a timed plan every `step` metres of travelled distance along its path (the
// waypoints' polyline): distances 0, step, 2 step, ... up to the path length, each with the
// plan's time there. Along the leg from waypoint i to i+1 the time goes linearly from
// waypoints[i].departure() to waypoints[i+1].eta; a sample landing exactly on a waypoint gets
// its arrival time, so a dwell shows as a jump of the time but not of the position. The first
// waypoint (at its eta) and the last (at its eta) are always included, the latter unless the
// last distance sample is already it. Empty plan: no samples. Throws std::invalid_argument
// unless step > 0 and finite.
std::vector<RouteSample> SamplePlan(const Plan& plan, double step);
// The same into `out` (cleared first), reusing its capacity: no allocation once warm, for the
// auction's ~1000 calls per order.
void SamplePlan(const Plan& plan, double step, std::vector<RouteSample>* out);

}  // namespace dispatch::engine
