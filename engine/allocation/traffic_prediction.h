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
// Zones: ZoneAt(xy) = the lowest zone id whose Zone::Contains(xy) holds (-1 if none), answered
// through a uniform grid over the floor (see TrafficPredictionConfig::zone_cell_size). A cell
// that lies (with a 1 mm margin) inside the lowest zone touching it answers directly; other
// cells keep the ids of the few zones touching them and test Contains on those in id order.
//
// Invariant: after SetPlan/RemovePlan the counts equal a recount from scratch over the current
// plans (a model test checks this). The predictor copies the zones it needs; it keeps no
// reference to the map. Not thread-safe: one writer (the allocator) at a time; const methods
// may run concurrently with each other.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

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
  static constexpr std::size_t kMaxZoneCells = std::size_t{1} << 21;
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
  // Builds the zone grid: O(cells of each zone's bounding box x its edges) once.
  // Throws std::invalid_argument on a non-positive or non-finite setting (broken contract).
  TrafficPredictor(const WarehouseMap& map, TrafficPredictionConfig config);

  // Replaces robot `robot`'s contribution with `plan` (adds it if new); an empty plan removes
  // it. O(buckets of the old and new plan x log waypoints). Storage grows to the plan's last
  // bucket. Throws std::invalid_argument on an empty robot id or non-finite plan times.
  void SetPlan(const std::string& robot, const Plan& plan);
  // Removes robot `robot`'s contribution; unknown robots are ignored.
  void RemovePlan(const std::string& robot);

  // The zone holding xy (lowest id on shared borders): O(1); -1 outside every zone.
  ZoneId ZoneAt(const Eigen::Vector2d& xy) const;
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

  // The same computation fed one sample at a time, for callers that already know a sample's
  // zone (the auction reuses the zones of an order's route for every bidder). Holds pointers
  // into the predictor: use it only while the predictor is not modified.
  class DensityAccumulator;

  // Buckets with storage: one past the last bucket any plan has reached (never shrinks).
  std::size_t bucket_count() const { return bucket_count_; }
  std::size_t robot_count() const { return robots_.size(); }
  const TrafficPredictionConfig& config() const { return config_; }
  // The grid actually used (after the kMaxZoneCells cap).
  double zone_cell_size() const { return cell_size_; }

 private:
  // What one robot's plan added: zones_[k] is its zone (or -1) at bucket first_bucket + k.
  struct Contribution {
    std::size_t first_bucket = 0;
    std::vector<ZoneId> zones;
  };

  void BuildZoneGrid(const Eigen::Vector2d& floor_min, const Eigen::Vector2d& floor_max);
  double BucketStart(std::size_t b) const;
  // bucket(t) as above; false for NaN or a bucket >= bucket_count_.
  bool StoredBucketOf(double t, std::size_t* bucket) const;
  void Apply(const Contribution& c, int sign);
  static ZoneId ZoneOf(const Contribution* c, std::size_t bucket);

  TrafficPredictionConfig config_;
  double inv_bucket_seconds_ = 2.0;  // 1 / bucket_seconds
  double inv_cell_size_ = 4.0;       // 1 / cell_size_
  std::vector<Zone> zones_;  // copies of the map's zones: polygons (Contains) and areas S_p

  // Zone grid: cell (cx, cy) covers origin + [cx, cx+1] x [cy, cy+1] * cell_size_. cells_ holds
  // a zone id (answers directly), -1 (no zone) or -2 - k: test Contains on
  // candidates_[candidate_begin_[k] .. candidate_begin_[k+1]) in that (id) order.
  Eigen::Vector2d grid_origin_ = Eigen::Vector2d::Zero();
  double cell_size_ = 0.25;
  std::int64_t grid_cols_ = 0;
  std::int64_t grid_rows_ = 0;
  std::vector<std::int32_t> cells_;
  std::vector<std::uint32_t> candidate_begin_;
  std::vector<ZoneId> candidates_;

  // counts_[b * zones_.size() + p]: robots in zone p at s_b, over all robots' plans.
  std::size_t bucket_count_ = 0;
  std::vector<std::int32_t> counts_;
  std::unordered_map<std::string, Contribution> robots_;
};

class TrafficPredictor::DensityAccumulator {
 public:
  // Counts exclude robot `robot`'s own plan (none when empty or unknown).
  DensityAccumulator(const TrafficPredictor& predictor, const std::string& robot);
  // A sample in `zone` (skipped when < 0) at time t.
  void Add(ZoneId zone, double t);
  void Add(const Eigen::Vector2d& xy, double t) { Add(predictor_->ZoneAt(xy), t); }
  // Eqs. (6)-(8) over the samples added so far; peaks sorted by zone id.
  DensityTerm Finish() const;

 private:
  const TrafficPredictor* predictor_;
  const Contribution* own_ = nullptr;
  std::vector<std::pair<ZoneId, int>> peaks_;  // N_p,max so far, in order of first visit
  std::size_t last_ = 0;                       // index of the last zone added
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
