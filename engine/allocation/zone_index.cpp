#include "engine/allocation/zone_index.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace dispatch::engine {
namespace {

// Grid cells are tested against zones grown by this margin (metres), far above both the
// rounding of the cell lookup and Zone::Contains' boundary tolerance (< 1e-4 m), so a cell
// that answers directly can never hold a point some other zone's Contains would accept.
constexpr double kCellMargin = 1e-3;

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

ZoneIndex::ZoneIndex(const WarehouseMap& map, double cell_size)
    : requested_cell_size_(cell_size), zones_(map.zones()) {
  if (!(cell_size > 0.0) || !std::isfinite(cell_size)) {
    throw std::invalid_argument("ZoneIndex: the cell size must be positive and finite");
  }
  BuildZoneGrid(map.floor_min(), map.floor_max());
  BuildArcZones(map);
}

void ZoneIndex::BuildZoneGrid(const Eigen::Vector2d& floor_min,
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
  const double max_cells = static_cast<double>(kMaxZoneCells);
  double cell = requested_cell_size_;
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

ZoneId ZoneIndex::ZoneAt(const Eigen::Vector2d& xy) const {
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

ZoneId ZoneIndex::UniformZoneIn(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) const {
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

void ZoneIndex::BuildArcZones(const WarehouseMap& map) {
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

}  // namespace dispatch::engine
