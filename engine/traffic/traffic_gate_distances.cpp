// TrafficGate's minimum distance between robots (SampleDistances): every pair of robots in
// neighbouring 1 m cells, where they really are, teammates excepted. The gate's other parts are
// listed in traffic_gate_impl.h.
#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/traffic/traffic_gate_impl.h"

namespace dispatch::engine {

void GateImpl::SampleDistances(double t) {
  // Robots in 1 m cells of a grid over the floor (linked lists through `distance_next`, no
  // allocation per sample); every pair in neighbouring cells is measured once, the earlier
  // robot in id order first. Team keys only for pairs closer than the minimum so far (rare
  // once it is near eps1).
  using Item = DistanceItem;
  if (distance_cols == 0) {  // the grid, once: the floor's bounds and a cell's margin
    Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector2d hi = -lo;
    for (const auto& p : map->points()) {
      lo = lo.cwiseMin(p.position);
      hi = hi.cwiseMax(p.position);
    }
    if (!std::isfinite(lo.x())) lo = hi = Eigen::Vector2d::Zero();
    distance_origin = lo - Eigen::Vector2d::Constant(2.0);
    distance_cols = static_cast<std::size_t>(std::ceil(hi.x() - distance_origin.x())) + 3;
    distance_rows = static_cast<std::size_t>(std::ceil(hi.y() - distance_origin.y())) + 3;
    distance_head.assign(distance_cols * distance_rows, -1);
  }
  const auto cols = static_cast<long long>(distance_cols), rows = static_cast<long long>(distance_rows);
  std::vector<Item>& items = distance_items;
  items.clear();
  for (GateBot* bot : in_order) {
    GateBot& b = *bot;
    if (!b.has_xy || !b.connected) continue;
    // Off the grid (a pose the floor's margin does not cover): the nearest border cell.
    const Eigen::Vector2d xy = b.xy.cwiseMax(distance_origin).cwiseMin(
        distance_origin + Eigen::Vector2d(static_cast<double>(distance_cols) - 1e-6, static_cast<double>(distance_rows) - 1e-6));
    // xy - origin >= 0 here: truncation is the floor.
    const Eigen::Vector2d rel = xy - distance_origin;
    const long long cx = std::clamp(static_cast<long long>(rel.x()), 0LL, cols - 1);
    const long long cy = std::clamp(static_cast<long long>(rel.y()), 0LL, rows - 1);
    const Eigen::Vector2d in_cell =
        xy == b.xy ? Eigen::Vector2d(rel.x() - static_cast<double>(cx), rel.y() - static_cast<double>(cy))
                   : Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
    items.push_back({b.xy, cx, cy, &b, in_cell});
  }
  if (++distance_stamp == 0) {
    std::fill(distance_keys_stamp.begin(), distance_keys_stamp.end(), 0);
    distance_stamp = 1;
  }
  if (distance_keys.size() < items.size()) {
    distance_keys.resize(items.size());
    distance_keys_stamp.resize(items.size(), 0);
  }
  auto keys_of = [this](std::size_t k) -> const GateTeamKeys& {
    if (distance_keys_stamp[k] != distance_stamp) {
      distance_keys[k] = TeamKeys(*distance_items[k].bot);
      distance_keys_stamp[k] = distance_stamp;
    }
    return distance_keys[k];
  };
  auto same_agent = [&](std::size_t a, std::size_t b) {
    const GateTeamKeys& kb = keys_of(b);
    for (const std::string& x : keys_of(a)) {
      if (!x.empty() && std::find(kb.begin(), kb.end(), x) != kb.end()) return true;
    }
    return false;
  };
  distance_next.assign(items.size(), -1);
  for (std::size_t k = 0; k < items.size(); ++k) {
    const Item& me = items[k];
    // A neighbouring cell is skipped when me is further than the minimum so far from the
    // side they share: every robot there is further than that too, and would be skipped
    // below (a margin far above rounding; a robot off the grid scans all nine).
    const double reach = min_distance.distance + 1e-9;
    const Eigen::Vector2d& f = me.in_cell;
    const bool all = std::isnan(f.x());  // off the grid
    const long long x0 = all || f.x() <= reach ? me.cx - 1 : me.cx;
    const long long x1 = all || 1.0 - f.x() <= reach ? me.cx + 1 : me.cx;
    const long long y0 = all || f.y() <= reach ? me.cy - 1 : me.cy;
    const long long y1 = all || 1.0 - f.y() <= reach ? me.cy + 1 : me.cy;
    for (long long x = std::max(x0, 0LL); x <= std::min(x1, cols - 1); ++x) {
      for (long long y = std::max(y0, 0LL); y <= std::min(y1, rows - 1); ++y) {
        for (int j = distance_head[static_cast<std::size_t>(y * cols + x)]; j >= 0;
             j = distance_next[static_cast<std::size_t>(j)]) {
          const auto jo = static_cast<std::size_t>(j);
          const double d = (items[jo].xy - me.xy).norm();
          if (d >= min_distance.distance || same_agent(jo, k)) continue;
          min_distance = {d, items[jo].bot->id, me.bot->id, t};
        }
      }
    }
    const auto c = static_cast<std::size_t>(me.cy * cols + me.cx);
    distance_next[k] = distance_head[c];  // the earlier robots only: each pair once
    distance_head[c] = static_cast<int>(k);
  }
  for (const Item& me : items) distance_head[static_cast<std::size_t>(me.cy * cols + me.cx)] = -1;
}

}  // namespace dispatch::engine
