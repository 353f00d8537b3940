#include "engine/allocation/traffic_prediction.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace dispatch::engine {
namespace {

// Grid cells are tested against zones grown by this margin (metres), far above both the
// rounding of the cell lookup and Zone::Contains' boundary tolerance (< 1e-4 m), so a cell
// that answers directly can never hold a point some other zone's Contains would accept.
constexpr double kCellMargin = 1e-3;

// Beyond this many buckets a plan's time span is treated as a broken contract.
constexpr double kMaxBuckets = 4.0e9;

// Does the closed segment a-b meet the closed box [lo, hi]? (Liang-Barsky clipping.)
bool SegmentTouchesBox(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                       const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) {
  double t0 = 0.0, t1 = 1.0;
  const Eigen::Vector2d d = b - a;
  for (int k = 0; k < 2; ++k) {
    if (d[k] == 0.0) {
      if (a[k] < lo[k] || a[k] > hi[k]) return false;
      continue;
    }
    double ta = (lo[k] - a[k]) / d[k];
    double tb = (hi[k] - a[k]) / d[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

enum class CellCover { kNone, kPartial, kFull };

// How zone `zone` covers the closed box: no edge meets it -> it is wholly inside or outside.
CellCover Cover(const Zone& zone, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) {
  const auto& poly = zone.polygon;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    if (SegmentTouchesBox(poly[j], poly[i], lo, hi)) return CellCover::kPartial;
  }
  return zone.Contains(0.5 * (lo + hi)) ? CellCover::kFull : CellCover::kNone;
}

}  // namespace

TrafficPredictor::TrafficPredictor(const WarehouseMap& map, TrafficPredictionConfig config)
    : config_(config), zones_(map.zones()) {
  if (!(config_.bucket_seconds > 0.0) || !std::isfinite(config_.bucket_seconds) ||
      !std::isfinite(config_.origin_time) || !(config_.zone_cell_size > 0.0) ||
      !std::isfinite(config_.zone_cell_size)) {
    throw std::invalid_argument("TrafficPredictionConfig: bucket_seconds and zone_cell_size "
                                "must be positive and finite, origin_time finite");
  }
  inv_bucket_seconds_ = 1.0 / config_.bucket_seconds;
  bucket_starts_ = {BucketStart(0)};
  BuildZoneGrid(map.floor_min(), map.floor_max());
  BuildArcZones(map);
}

// --- Zone grid ------------------------------------------------------------------------------

void TrafficPredictor::BuildZoneGrid(const Eigen::Vector2d& floor_min,
                                     const Eigen::Vector2d& floor_max) {
  // The grid spans the floor and every zone plus one cell on each side; a point beyond it is
  // more than a cell away from every zone.
  Eigen::Vector2d lo = floor_min.cwiseMin(floor_max);
  Eigen::Vector2d hi = floor_min.cwiseMax(floor_max);
  for (const Zone& zone : zones_) {
    for (const Eigen::Vector2d& v : zone.polygon) {
      lo = lo.cwiseMin(v);
      hi = hi.cwiseMax(v);
    }
  }
  const Eigen::Vector2d size = hi - lo;
  const auto cells_for = [&](double cell) {
    return (std::floor(size.x() / cell) + 3.0) * (std::floor(size.y() / cell) + 3.0);
  };
  const double max_cells = static_cast<double>(TrafficPredictionConfig::kMaxZoneCells);
  double cell = config_.zone_cell_size;
  if (cells_for(cell) > max_cells) {
    cell = std::max(cell, std::sqrt(size.x() * size.y() / max_cells));
    while (cells_for(cell) > max_cells) cell *= 1.01;
  }
  cell_size_ = cell;
  inv_cell_size_ = 1.0 / cell;
  grid_origin_ = lo - Eigen::Vector2d::Constant(cell);
  grid_cols_ = static_cast<std::int64_t>(std::floor(size.x() / cell)) + 3;
  grid_rows_ = static_cast<std::int64_t>(std::floor(size.y() / cell)) + 3;
  const std::size_t n_cells = static_cast<std::size_t>(grid_cols_ * grid_rows_);

  // Per cell while building: -1 untouched, >= 0 wholly inside that (lowest touching) zone,
  // kOpen: only partially covering candidates so far, kClosed: the last candidate covers it
  // wholly, so higher ids can never answer there.
  constexpr std::int32_t kOpen = -2, kClosed = -3;
  std::vector<std::int32_t> state(n_cells, -1);
  std::vector<std::pair<std::uint32_t, ZoneId>> pairs;  // (cell, candidate), in zone order
  for (std::size_t z = 0; z < zones_.size(); ++z) {
    const Zone& zone = zones_[z];
    if (zone.polygon.size() < 3) continue;
    Eigen::Vector2d zlo = zone.polygon.front(), zhi = zone.polygon.front();
    for (const Eigen::Vector2d& v : zone.polygon) {
      zlo = zlo.cwiseMin(v);
      zhi = zhi.cwiseMax(v);
    }
    // Cell range of the zone's bounding box, one cell wider on each side (still inside the
    // grid, which has a spare cell around every zone).
    const auto cell_index = [&](double v, double origin, std::int64_t n) {
      const double f = std::floor((v - origin) / cell);
      return static_cast<std::int64_t>(std::clamp(f, 1.0, static_cast<double>(n - 2)));
    };
    const std::int64_t cx0 = cell_index(zlo.x(), grid_origin_.x(), grid_cols_) - 1;
    const std::int64_t cx1 = cell_index(zhi.x(), grid_origin_.x(), grid_cols_) + 1;
    const std::int64_t cy0 = cell_index(zlo.y(), grid_origin_.y(), grid_rows_) - 1;
    const std::int64_t cy1 = cell_index(zhi.y(), grid_origin_.y(), grid_rows_) + 1;
    for (std::int64_t cy = cy0; cy <= cy1; ++cy) {
      for (std::int64_t cx = cx0; cx <= cx1; ++cx) {
        const std::size_t c = static_cast<std::size_t>(cy * grid_cols_ + cx);
        std::int32_t& st = state[c];
        if (st >= 0 || st == kClosed) continue;  // a lower id already answers everywhere here
        const Eigen::Vector2d corner(static_cast<double>(cx), static_cast<double>(cy));
        const Eigen::Vector2d box_lo =
            grid_origin_ + cell * corner - Eigen::Vector2d::Constant(kCellMargin);
        const Eigen::Vector2d box_hi = box_lo + Eigen::Vector2d::Constant(cell + 2 * kCellMargin);
        const CellCover cover = Cover(zone, box_lo, box_hi);
        if (cover == CellCover::kNone) continue;
        if (cover == CellCover::kFull && st == -1) {
          st = static_cast<std::int32_t>(z);
          continue;
        }
        pairs.emplace_back(static_cast<std::uint32_t>(c), static_cast<ZoneId>(z));
        st = cover == CellCover::kFull ? kClosed : kOpen;
      }
    }
  }
  std::stable_sort(pairs.begin(), pairs.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });

  cells_.assign(n_cells, -1);
  candidate_begin_.clear();
  candidates_.clear();
  candidates_.reserve(pairs.size());
  for (std::size_t c = 0; c < n_cells; ++c) {
    if (state[c] >= 0) cells_[c] = state[c];
  }
  for (std::size_t i = 0; i < pairs.size();) {
    const std::uint32_t c = pairs[i].first;
    cells_[c] = -2 - static_cast<std::int32_t>(candidate_begin_.size());
    candidate_begin_.push_back(static_cast<std::uint32_t>(candidates_.size()));
    for (; i < pairs.size() && pairs[i].first == c; ++i) candidates_.push_back(pairs[i].second);
  }
  candidate_begin_.push_back(static_cast<std::uint32_t>(candidates_.size()));
}

ZoneId TrafficPredictor::ZoneAt(const Eigen::Vector2d& xy) const {
  const double fx = (xy.x() - grid_origin_.x()) * inv_cell_size_;
  const double fy = (xy.y() - grid_origin_.y()) * inv_cell_size_;
  // Also rejects NaN.
  if (!(fx >= 0.0 && fy >= 0.0 && fx < static_cast<double>(grid_cols_) &&
        fy < static_cast<double>(grid_rows_))) {
    return -1;
  }
  const std::int64_t cell = static_cast<std::int64_t>(fy) * grid_cols_ +
                           static_cast<std::int64_t>(fx);
  const std::int32_t v = cells_[static_cast<std::size_t>(cell)];
  if (v >= -1) return v;
  const std::size_t k = static_cast<std::size_t>(-2 - v);
  for (std::uint32_t i = candidate_begin_[k]; i < candidate_begin_[k + 1]; ++i) {
    const ZoneId z = candidates_[i];
    if (zones_[static_cast<std::size_t>(z)].Contains(xy)) return z;
  }
  return -1;
}

ZoneId TrafficPredictor::UniformZoneIn(const Eigen::Vector2d& lo,
                                       const Eigen::Vector2d& hi) const {
  // The cell of a coordinate is monotone in it (rounded subtraction and multiplication by a
  // positive factor, then truncation, are all monotone), so every point of [lo, hi] lies in a
  // cell of the range computed from the corners, as ZoneAt computes it.
  const double fx0 = (lo.x() - grid_origin_.x()) * inv_cell_size_;
  const double fy0 = (lo.y() - grid_origin_.y()) * inv_cell_size_;
  const double fx1 = (hi.x() - grid_origin_.x()) * inv_cell_size_;
  const double fy1 = (hi.y() - grid_origin_.y()) * inv_cell_size_;
  if (!(fx0 >= 0.0 && fy0 >= 0.0 && fx1 < static_cast<double>(grid_cols_) &&
        fy1 < static_cast<double>(grid_rows_))) {
    return kMixedZone;  // partly off the grid (or NaN): leave it to ZoneAt
  }
  const std::int64_t cx0 = static_cast<std::int64_t>(fx0), cx1 = static_cast<std::int64_t>(fx1);
  const std::int64_t cy0 = static_cast<std::int64_t>(fy0), cy1 = static_cast<std::int64_t>(fy1);
  constexpr std::int64_t kMaxCells = 4096;  // long diagonal arcs: not worth the scan
  if ((cx1 - cx0 + 1) * (cy1 - cy0 + 1) > kMaxCells) return kMixedZone;
  const std::int32_t v = cells_[static_cast<std::size_t>(cy0 * grid_cols_ + cx0)];
  if (v < -1) return kMixedZone;
  for (std::int64_t cy = cy0; cy <= cy1; ++cy) {
    for (std::int64_t cx = cx0; cx <= cx1; ++cx) {
      if (cells_[static_cast<std::size_t>(cy * grid_cols_ + cx)] != v) return kMixedZone;
    }
  }
  return v;
}

void TrafficPredictor::BuildArcZones(const WarehouseMap& map) {
  arc_zones_.assign(map.arcs().size(), kMixedZone);
  for (std::size_t i = 0; i < map.arcs().size(); ++i) {
    const Arc& arc = map.arcs()[i];
    const Eigen::Vector2d& a = map.point(arc.from).position;
    const Eigen::Vector2d& b = map.point(arc.to).position;
    if (!a.allFinite() || !b.allFinite()) continue;
    // A point a + f (b - a) computed in doubles strays from the box by a few ulps of the
    // coordinates; the margin is far above that.
    const double scale = std::max({1.0, a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff()});
    const Eigen::Vector2d margin = Eigen::Vector2d::Constant(1e-6 * scale);
    arc_zones_[i] = UniformZoneIn(a.cwiseMin(b) - margin, a.cwiseMax(b) + margin);
  }
}

// --- Buckets and counts ---------------------------------------------------------------------

void TrafficPredictor::Apply(const Contribution& c, int sign) {
  for (std::size_t k = 0; k < c.zones.size(); ++k) {
    if (c.zones[k] < 0) continue;
    counts_[static_cast<std::size_t>(c.zones[k]) * bucket_stride_ + c.first_bucket + k] += sign;
  }
}

TrafficPredictor::PlanHandle TrafficPredictor::SetPlan(const std::string& robot,
                                                       const Plan& plan) {
  if (robot.empty()) throw std::invalid_argument("TrafficPredictor::SetPlan: empty robot id");
  if (plan.waypoints.empty()) {
    RemovePlan(robot);
    return PlanHandle{};
  }
  const double start = plan.start_time(), end = plan.end_time();
  if (!std::isfinite(start) || !std::isfinite(end)) {
    throw std::invalid_argument("TrafficPredictor::SetPlan: non-finite plan times for " + robot);
  }
  Contribution next;
  const double origin = config_.origin_time, dt = config_.bucket_seconds;
  if (end >= origin && start <= end) {
    // First bucket: the smallest b >= 0 with s_b >= start; last: the largest with s_b <= end.
    const double q0 = std::max(0.0, std::ceil((start - origin) / dt));
    const double q1 = std::floor((end - origin) / dt);
    if (q1 > kMaxBuckets) {
      throw std::invalid_argument("TrafficPredictor::SetPlan: plan of " + robot +
                                  " ends too far after origin_time");
    }
    std::size_t first = static_cast<std::size_t>(std::min(q0, q1 + 2.0));
    while (first > 0 && BucketStart(first - 1) >= start) --first;
    while (BucketStart(first) < start) ++first;
    std::size_t last_plus_one = static_cast<std::size_t>(std::max(q1, 0.0));
    while (last_plus_one > 0 && BucketStart(last_plus_one) > end) --last_plus_one;
    while (BucketStart(last_plus_one) <= end) ++last_plus_one;  // now one past the last
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
        const double t = BucketStart(b);
        Eigen::Vector2d xy;
        if (t <= w.front().eta) {
          xy = w.front().xy;
        } else {
          while (upper < w.size() && !(t < w[upper].eta)) ++upper;
          const Waypoint& from = w[upper - 1];
          if (upper == w.size() || t <= from.departure()) {
            xy = from.xy;
          } else {
            const Waypoint& to = w[upper];
            const double span = to.eta - from.departure();
            xy = span <= 0.0 ? to.xy : Eigen::Vector2d(from.xy + ((t - from.departure()) / span) * (to.xy - from.xy));
          }
        }
        if (!(xy == last_xy)) {
          last_zone = ZoneAt(xy);
          last_xy = xy;
        }
        next.zones.push_back(last_zone);
      }
      next.tail = next.zones.size();
      while (next.tail > 0 && next.zones[next.tail - 1] == next.zones.back()) --next.tail;
      if (last_plus_one > bucket_stride_) {
        // Zone-major rows grow by doubling (amortised O(1) per bucket); the tail stays 0.
        const std::size_t stride = std::max(last_plus_one, 2 * bucket_stride_);
        std::vector<std::int32_t> grown(stride * zones_.size(), 0);
        for (std::size_t z = 0; z < zones_.size(); ++z) {
          std::copy_n(counts_.begin() + static_cast<std::ptrdiff_t>(z * bucket_stride_),
                      bucket_count_, grown.begin() + static_cast<std::ptrdiff_t>(z * stride));
        }
        counts_ = std::move(grown);
        bucket_stride_ = stride;
      }
      for (std::size_t b = bucket_count_ + 1; b <= last_plus_one; ++b) {
        bucket_starts_.push_back(BucketStart(b));
      }
      bucket_count_ = std::max(bucket_count_, last_plus_one);
    }
  }
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
  if (zone < 0 || static_cast<std::size_t>(zone) >= zones_.size()) return 0;
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
}

void TrafficPredictor::DensityAccumulator::NewZone(ZoneId zone, int n) {
  last_ = 0;
  while (last_ < peaks_.size() && peaks_[last_].first != zone) ++last_;
  if (last_ == peaks_.size()) peaks_.emplace_back(zone, n);
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
  if (last_ >= peaks_.size() || peaks_[last_].first != zone) NewZone(zone, peak);
  peaks_[last_].second = std::max(peaks_[last_].second, peak);
}

void TrafficPredictor::DensityAccumulator::AddAtMost(ZoneId zone, double t, double slack) {
  if (zone < 0) return;
  const TrafficPredictor& p = *predictor_;
  const std::int32_t* row = p.counts_.data() + static_cast<std::size_t>(zone) * p.bucket_stride_;
  const double* starts = p.bucket_starts_.data();  // bucket_count_ + 1 entries
  int n = 0;  // an unstored bucket in the window (or a NaN time): no robot there
  std::size_t lo = 0;
  if (Locate(t - slack, &lo)) {
    // hi = bucket(t + slack): from lo up (s_b is non-decreasing in b).
    const double t_hi = t + slack;
    std::size_t hi = lo;
    while (hi < p.bucket_count_ && starts[hi + 1] <= t_hi) ++hi;
    if (hi < p.bucket_count_) {
      n = std::numeric_limits<int>::max();
      for (std::size_t b = lo; b <= hi; ++b) {
        n = std::min(n, row[b] - (OwnZone(b) == zone ? 1 : 0));
      }
    }
  }
  if (last_ >= peaks_.size() || peaks_[last_].first != zone) NewZone(zone, n);
  peaks_[last_].second = std::max(peaks_[last_].second, n);
}

double TrafficPredictor::DensityAccumulator::Flow() {
  sorted_ = peaks_;
  std::sort(sorted_.begin(), sorted_.end());
  double flow = 0.0;
  for (const auto& [z, n_max] : sorted_) {
    flow += n_max / predictor_->zones_[static_cast<std::size_t>(z)].area;  // eqs. (7)-(8)
  }
  return flow;
}

DensityTerm TrafficPredictor::DensityAccumulator::Finish() const {
  DensityTerm term;
  term.peaks = peaks_;
  std::sort(term.peaks.begin(), term.peaks.end());
  for (const auto& [z, n_max] : term.peaks) {
    term.flow += n_max / predictor_->zones_[static_cast<std::size_t>(z)].area;  // eqs. (7)-(8)
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
