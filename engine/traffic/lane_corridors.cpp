#include "engine/traffic/lane_corridors.h"

#include <algorithm>

namespace dispatch::engine {

int LaneCorridors::Direction(const WarehouseMap& map, ArcId arc) const {
  const Arc& a = map.arc(arc);
  const auto path = static_cast<std::size_t>(a.path);
  const LaneCorridor& c = corridors[static_cast<std::size_t>(corridor_of_path[path])];
  return c.points[static_cast<std::size_t>(index_in_corridor[path])] == a.from ? +1 : -1;
}

LaneCorridors BuildLaneCorridors(const WarehouseMap& map) {
  const std::size_t n = map.point_count();
  const auto& paths = map.paths();
  // Undirected incidence: paths touching each point.
  std::vector<std::vector<std::int32_t>> incident(n);
  for (std::size_t p = 0; p < paths.size(); ++p) {
    incident[static_cast<std::size_t>(paths[p].from)].push_back(static_cast<std::int32_t>(p));
    incident[static_cast<std::size_t>(paths[p].to)].push_back(static_cast<std::int32_t>(p));
  }
  auto interior = [&](PointId v) {
    const auto& in = incident[static_cast<std::size_t>(v)];
    if (in.size() != 2) return false;
    const Path& a = paths[static_cast<std::size_t>(in[0])];
    const Path& b = paths[static_cast<std::size_t>(in[1])];
    if (!a.bidirectional || !b.bidirectional) return false;
    const PointId oa = a.from == v ? a.to : a.from;
    const PointId ob = b.from == v ? b.to : b.from;
    return oa != ob;
  };
  auto other = [&](std::int32_t path, PointId v) {
    const Path& p = paths[static_cast<std::size_t>(path)];
    return p.from == v ? p.to : p.from;
  };
  auto next_path = [&](PointId v, std::int32_t came) {
    const auto& in = incident[static_cast<std::size_t>(v)];
    return in[0] == came ? in[1] : in[0];
  };

  LaneCorridors out;
  out.corridor_of_path.assign(paths.size(), -1);
  out.index_in_corridor.assign(paths.size(), -1);
  out.interior_of.assign(n, -1);
  for (std::size_t p0 = 0; p0 < paths.size(); ++p0) {
    if (!paths[p0].bidirectional || out.corridor_of_path[p0] >= 0) continue;
    const int id = static_cast<int>(out.corridors.size());
    // Walk backwards from `from` to the chain's start, then forwards to its end.
    std::vector<std::int32_t> back;
    PointId v = paths[p0].from;
    std::int32_t came = static_cast<std::int32_t>(p0);
    bool ring = false;
    while (interior(v)) {
      const std::int32_t q = next_path(v, came);
      if (q == static_cast<std::int32_t>(p0)) {
        ring = true;
        break;
      }
      back.push_back(q);
      came = q;
      v = other(q, v);
    }
    LaneCorridor c;
    std::reverse(back.begin(), back.end());
    // Chain start point: v (when not a ring), then the paths in order.
    PointId cur = ring ? paths[p0].to : v;
    for (std::int32_t q : back) {
      c.points.push_back(cur);
      c.paths.push_back(q);
      cur = other(q, cur);
    }
    c.points.push_back(cur);
    c.paths.push_back(static_cast<std::int32_t>(p0));
    cur = other(static_cast<std::int32_t>(p0), cur);
    came = static_cast<std::int32_t>(p0);
    while (!ring && interior(cur)) {
      const std::int32_t q = next_path(cur, came);
      if (out.corridor_of_path[static_cast<std::size_t>(q)] == id ||
          q == static_cast<std::int32_t>(p0)) {
        break;
      }
      c.points.push_back(cur);
      c.paths.push_back(q);
      came = q;
      cur = other(q, cur);
    }
    c.points.push_back(cur);
    for (std::size_t k = 0; k < c.paths.size(); ++k) {
      out.corridor_of_path[static_cast<std::size_t>(c.paths[k])] = id;
      out.index_in_corridor[static_cast<std::size_t>(c.paths[k])] = static_cast<int>(k);
    }
    for (std::size_t k = 1; k + 1 < c.points.size(); ++k) {
      out.interior_of[static_cast<std::size_t>(c.points[k])] = id;
    }
    if (ring) out.interior_of[static_cast<std::size_t>(c.points.front())] = id;
    out.corridors.push_back(std::move(c));
  }
  return out;
}

}  // namespace dispatch::engine
