#include "engine/map/chu2024_floor.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "engine/common/text.h"
#include "engine/map/map_builder.h"

namespace dispatch::engine {

namespace {

// Layout constants (metres); chu2024_floor.md explains each.
constexpr int kShelfRows = 5;
constexpr int kShelfCols = 6;
constexpr double kShelfX0 = 3.75;      // left edge of shelf column 1
constexpr double kShelfWidth = 2.0;    // along x; slots at +0.25, +1.0, +1.75
constexpr double kColumnPitch = 5.0;
constexpr double kShelfY0 = 3.25;      // bottom edge of shelf row 1
constexpr double kShelfDepth = 1.0;
constexpr double kRowPitch = 4.0;
constexpr double kSlotOffsets[3] = {0.25, 1.0, 1.75};
constexpr double kStationSpur = 1.5;   // station distance from the outer ring lane

enum class Dir { kPlus, kMinus };  // +x/+y or -x/-y along the line

struct Line {
  bool vertical;
  double at;  // x of a vertical line, y of a horizontal one
  Dir dir;
  std::string name;
};

// Lane pairs: {lower coordinate, upper coordinate}. Right-hand traffic: southbound at the lower
// x of a vertical pair, eastbound at the lower y of a horizontal pair.
std::vector<std::pair<double, double>> VerticalPairs() {
  std::vector<std::pair<double, double>> pairs = {{-0.25, 1.25}};  // left ring
  for (int k = 0; k < kShelfCols - 1; ++k) pairs.push_back({6.5 + 5.0 * k, 8.0 + 5.0 * k});
  pairs.push_back({33.25, 34.75});  // right ring
  return pairs;
}

std::vector<std::pair<double, double>> HorizontalPairs() {
  std::vector<std::pair<double, double>> pairs = {{0.25, 1.75}};  // bottom ring
  for (int j = 0; j < kShelfRows - 1; ++j) pairs.push_back({5.0 + 4.0 * j, 6.5 + 4.0 * j});
  pairs.push_back({21.75, 23.25});  // top ring
  return pairs;
}

// Nodes placed on one line, keyed by their coordinate along it.
using LineNodes = std::map<double, std::string>;

}  // namespace

std::vector<Eigen::Vector2d> Chu2024FloorOptions::Row4NorthFaceDocks() {
  std::vector<Eigen::Vector2d> docks;
  const double y = kShelfY0 + kRowPitch * 3 + kShelfDepth + 0.25;  // 16.5
  for (int c = 0; c < kShelfCols; ++c) {
    for (double dx : kSlotOffsets) docks.push_back({kShelfX0 + kColumnPitch * c + dx, y});
  }
  return docks;
}

std::vector<std::string> Chu2024StationNames() {
  std::vector<std::string> names;
  for (int i = 1; i <= 18; ++i) names.push_back("P" + std::to_string(i));
  return names;
}

Result<WarehouseMap> BuildChu2024Floor(const Chu2024FloorOptions& options) {
  MapBuilder b("chu2024");
  const auto vpairs = VerticalPairs();
  const auto hpairs = HorizontalPairs();
  const double x_lo = vpairs.front().first, x_hi = vpairs.back().second;
  const double y_lo = hpairs.front().first, y_hi = hpairs.back().second;
  const Eigen::Vector2d floor_min(x_lo - kStationSpur - 0.75, y_lo - kStationSpur - 0.75);
  const Eigen::Vector2d floor_max(x_hi + kStationSpur + 0.75, y_hi + kStationSpur + 0.75);
  b.SetFloor(floor_min, floor_max);

  // 6 zones: 3 columns x 2 rows, cut through the middle of shelf columns' gaps and shelf row 3.
  const double xcuts[4] = {floor_min.x(), 12.25, 22.25, floor_max.x()};
  const double ycuts[3] = {floor_min.y(), 11.75, floor_max.y()};
  for (int r = 0; r < 2; ++r) {
    for (int c = 0; c < 3; ++c) {
      b.AddRectZone("Z" + std::to_string(r * 3 + c + 1), {xcuts[c], ycuts[r]},
                    {xcuts[c + 1], ycuts[r + 1]});
    }
  }

  // Shelves.
  for (int r = 0; r < kShelfRows; ++r) {
    for (int c = 0; c < kShelfCols; ++c) {
      const Eigen::Vector2d lo(kShelfX0 + kColumnPitch * c, kShelfY0 + kRowPitch * r);
      b.AddShelf("S" + std::to_string(r + 1) + "-" + std::to_string(c + 1), lo,
                 lo + Eigen::Vector2d(kShelfWidth, kShelfDepth));
    }
  }

  // Lines.
  std::vector<Line> lines;
  for (std::size_t p = 0; p < vpairs.size(); ++p) {
    lines.push_back({true, vpairs[p].first, Dir::kMinus, "V" + std::to_string(2 * p)});
    lines.push_back({true, vpairs[p].second, Dir::kPlus, "V" + std::to_string(2 * p + 1)});
  }
  for (std::size_t p = 0; p < hpairs.size(); ++p) {
    lines.push_back({false, hpairs[p].first, Dir::kPlus, "H" + std::to_string(2 * p)});
    lines.push_back({false, hpairs[p].second, Dir::kMinus, "H" + std::to_string(2 * p + 1)});
  }
  std::vector<LineNodes> nodes(lines.size());
  auto pos = [&](const Line& l, double along) {
    return l.vertical ? Eigen::Vector2d(l.at, along) : Eigen::Vector2d(along, l.at);
  };
  auto add_node = [&](std::size_t line, double along, const std::string& name, PointKind kind) {
    nodes[line][along] = name;
    if (!b.HasPoint(name)) b.AddPoint(name, pos(lines[line], along), kind);
  };
  auto line_index = [&](bool vertical, double at) -> std::size_t {
    for (std::size_t i = 0; i < lines.size(); ++i) {
      if (lines[i].vertical == vertical && lines[i].at == at) return i;
    }
    return lines.size();
  };

  // Crossings: every vertical line meets every horizontal line; each pair x pair block of 4
  // crossings is one intersection's inner region I_w.
  auto crossing_name = [](std::size_t vl, std::size_t hl) {
    return "X" + std::to_string(vl) + "-" + std::to_string(hl);
  };
  for (std::size_t vl = 0; vl < 2 * vpairs.size(); ++vl) {
    for (std::size_t h = 0; h < 2 * hpairs.size(); ++h) {
      const std::size_t hl = 2 * vpairs.size() + h;
      const std::string name = crossing_name(vl, h);
      add_node(vl, lines[hl].at, name, PointKind::kIntersection);
      add_node(hl, lines[vl].at, name, PointKind::kIntersection);
    }
  }

  // Approach points O_w: on every line, `approach_distance` before each crossing pair that the
  // line enters from a previous segment.
  std::map<std::pair<std::size_t, std::size_t>, std::vector<std::string>> approaches;
  for (std::size_t li = 0; li < lines.size(); ++li) {
    const Line& l = lines[li];
    const auto& pairs = l.vertical ? hpairs : vpairs;
    for (std::size_t p = 0; p < pairs.size(); ++p) {
      const bool first_along = l.dir == Dir::kPlus ? p == 0 : p + 1 == pairs.size();
      if (first_along) continue;
      const double along = l.dir == Dir::kPlus ? pairs[p].first - options.approach_distance
                                               : pairs[p].second + options.approach_distance;
      const std::string name = l.name + "-O" + std::to_string(p);
      add_node(li, along, name, PointKind::kLane);
      const auto key = l.vertical ? std::make_pair(li / 2, p) : std::make_pair(p, (li - 2 * vpairs.size()) / 2);
      approaches[key].push_back(name);
    }
  }

  // Pick points: on each aisle lane, at the three slot positions of every shelf column. The
  // lane below a shelf row serves its south face, the lane above serves its north face.
  for (std::size_t hp = 1; hp + 1 < hpairs.size(); ++hp) {
    for (int side = 0; side < 2; ++side) {
      const double y = side == 0 ? hpairs[hp].first : hpairs[hp].second;
      const std::size_t li = line_index(false, y);
      // hp-th aisle lies between shelf rows hp (below) and hp+1 (above), 1-based.
      const int row = side == 0 ? static_cast<int>(hp) : static_cast<int>(hp) + 1;
      const char face = side == 0 ? 'N' : 'S';
      for (int c = 0; c < kShelfCols; ++c) {
        for (int s = 0; s < 3; ++s) {
          const double x = kShelfX0 + kColumnPitch * c + kSlotOffsets[s];
          add_node(li, x,
                   "K" + std::to_string(row) + "-" + std::to_string(c + 1) + "-" +
                       std::to_string(s + 1) + face,
                   PointKind::kPick);
        }
      }
    }
  }

  // Drop points where the aisles leave the shelf block (one per aisle lane that exits it):
  // bottom on southbound lanes, top on northbound, left on westbound, right on eastbound.
  const double block_lo_x = kShelfX0, block_hi_x = kShelfX0 + kColumnPitch * 5 + kShelfWidth;
  const double block_lo_y = kShelfY0, block_hi_y = kShelfY0 + kRowPitch * 4 + kShelfDepth;
  const double drop_gap_x = 1.5, drop_gap_y = 0.5;  // drop point distance from the block
  for (std::size_t vp = 1; vp + 1 < vpairs.size(); ++vp) {
    add_node(line_index(true, vpairs[vp].first), block_lo_y - drop_gap_y,
             "D-B" + std::to_string(vp), PointKind::kDrop);
    add_node(line_index(true, vpairs[vp].second), block_hi_y + drop_gap_y,
             "D-T" + std::to_string(vp), PointKind::kDrop);
  }
  for (std::size_t hp = 1; hp + 1 < hpairs.size(); ++hp) {
    add_node(line_index(false, hpairs[hp].second), block_lo_x - drop_gap_x,
             "D-L" + std::to_string(hp), PointKind::kDrop);
    add_node(line_index(false, hpairs[hp].first), block_hi_x + drop_gap_x,
             "D-R" + std::to_string(hp), PointKind::kDrop);
  }

  // Parking stations outside the outer ring lanes, counterclockwise from the bottom-left:
  // 6 below, 3 right, 6 above, 3 left. Each hangs off a junction on the outer lane by a
  // bidirectional single lane (single entry/exit, seed 000 §4.1).
  struct StationSpot {
    std::size_t line;
    double along;
    Eigen::Vector2d outward;
  };
  std::vector<StationSpot> spots;
  auto gap_mids = [](const std::vector<std::pair<double, double>>& pairs) {
    std::vector<double> mids;
    for (std::size_t i = 0; i + 1 < pairs.size(); ++i) {
      mids.push_back((pairs[i].second + pairs[i + 1].first) / 2);
    }
    return mids;
  };
  const auto xm = gap_mids(vpairs);  // 6 gaps between vertical pairs
  const auto ym = gap_mids(hpairs);  // 5 gaps between horizontal pairs
  for (double x : xm) spots.push_back({line_index(false, y_lo), x, {0, -1}});
  for (int i = 1; i <= 3; ++i) spots.push_back({line_index(true, x_hi), ym[i], {1, 0}});
  for (auto it = xm.rbegin(); it != xm.rend(); ++it) {
    spots.push_back({line_index(false, y_hi), *it, {0, 1}});
  }
  for (int i = 3; i >= 1; --i) spots.push_back({line_index(true, x_lo), ym[i], {-1, 0}});
  for (std::size_t i = 0; i < spots.size(); ++i) {
    const std::string station = "P" + std::to_string(i + 1);
    const std::string junction = "J" + std::to_string(i + 1);
    add_node(spots[i].line, spots[i].along, junction, PointKind::kLane);
    const Eigen::Vector2d at = pos(lines[spots[i].line], spots[i].along) +
                               kStationSpur * spots[i].outward;
    b.AddPoint("park-" + station, at, PointKind::kPark);
    b.AddPath(junction, "park-" + station, std::nullopt, 0.0, /*bidirectional=*/true);
    b.AddStation(station, "park-" + station, options.station_capacity);
  }

  // Pick docks off the lanes.
  for (const Eigen::Vector2d& dock : options.extra_pick_docks) {
    // Joined to the nearest lane or pick point (never to an intersection's inner region).
    std::string lane_point;
    double best = 1e18;
    for (std::size_t li = 0; li < lines.size(); ++li) {
      for (const auto& [along, name] : nodes[li]) {
        const double d = (pos(lines[li], along) - dock).norm();
        if (d < best && d > 1e-9 && name[0] != 'X') {
          best = d;
          lane_point = name;
        }
      }
    }
    if (lane_point.empty() || best > 2.0) {
      return InvalidArgument("pick dock (" + Number(dock.x()) + ", " + Number(dock.y()) +
                             ") has no lane point within 2 m");
    }
    const std::string name = "K-dock-" + Number(dock.x()) + "-" + Number(dock.y());
    b.AddPoint(name, dock, PointKind::kPick);
    b.AddPath(lane_point, name, std::nullopt, 0.0, /*bidirectional=*/true);
  }

  // One-way arcs between consecutive nodes of every line, in the line's direction.
  for (std::size_t li = 0; li < lines.size(); ++li) {
    const LineNodes& ln = nodes[li];
    std::vector<std::string> order;
    for (const auto& [along, name] : ln) order.push_back(name);
    if (lines[li].dir == Dir::kMinus) std::reverse(order.begin(), order.end());
    for (std::size_t i = 0; i + 1 < order.size(); ++i) b.AddPath(order[i], order[i + 1]);
  }

  // Intersections: inner = the 4 crossings of a vertical pair with a horizontal pair.
  for (std::size_t vp = 0; vp < vpairs.size(); ++vp) {
    for (std::size_t hp = 0; hp < hpairs.size(); ++hp) {
      std::vector<std::string> inner;
      for (int a = 0; a < 2; ++a) {
        for (int c = 0; c < 2; ++c) inner.push_back(crossing_name(2 * vp + a, 2 * hp + c));
      }
      b.AddIntersection("I" + std::to_string(vp) + "-" + std::to_string(hp), inner,
                        approaches[{vp, hp}]);
    }
  }
  return b.Build();
}

}  // namespace dispatch::engine
