#include "engine/motion/occupancy_grid.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <limits>
#include <queue>
#include <stdexcept>
#include <tuple>

namespace dispatch::engine {

OccupancyGrid::OccupancyGrid(int width, int height, double resolution, Eigen::Vector2d origin)
    : width_(width), height_(height), resolution_(resolution), origin_(std::move(origin)) {
  if (width < 1 || height < 1 || !(resolution > 0.0)) {
    throw std::invalid_argument("OccupancyGrid: width, height >= 1 and resolution > 0 required");
  }
  cells_.assign(static_cast<std::size_t>(width) * height, 0);
}

Result<OccupancyGrid> OccupancyGrid::FromMap(const WarehouseMap& map, double resolution) {
  if (!(resolution > 0.0)) return InvalidArgument("occupancy grid: resolution must be > 0");
  const Eigen::Vector2d size = map.floor_max() - map.floor_min();
  const double cells = std::ceil(size.x() / resolution) * std::ceil(size.y() / resolution);
  if (!(size.x() > 0.0 && size.y() > 0.0) || cells > 1e8) {
    return InvalidArgument("occupancy grid: floor of " + std::to_string(size.x()) + " x " +
                           std::to_string(size.y()) + " m at " + std::to_string(resolution) +
                           " m cells is empty or too large");
  }
  OccupancyGrid grid(static_cast<int>(std::ceil(size.x() / resolution - 1e-9)),
                     static_cast<int>(std::ceil(size.y() / resolution - 1e-9)), resolution, map.floor_min());
  for (const Shelf& shelf : map.shelves()) grid.SetRect(shelf.min, shelf.max, true);
  grid.ComputeClearance();
  return grid;
}

Result<OccupancyGrid> OccupancyGrid::FromMovingAi(std::string_view text, double tile, int subdivide) {
  if (!(tile > 0.0) || subdivide < 1) return InvalidArgument("movingai grid: tile > 0 and subdivide >= 1 required");
  std::vector<std::string_view> lines;
  for (std::size_t at = 0; at <= text.size();) {
    std::size_t end = text.find('\n', at);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(at, end - at);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    lines.push_back(line);
    at = end + 1;
  }
  int width = 0;
  int height = 0;
  std::size_t row0 = 0;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string_view line = lines[i];
    if (line.rfind("height ", 0) == 0) height = std::atoi(std::string(line.substr(7)).c_str());
    if (line.rfind("width ", 0) == 0) width = std::atoi(std::string(line.substr(6)).c_str());
    if (line == "map") {
      row0 = i + 1;
      break;
    }
  }
  if (row0 == 0 || width < 1 || height < 1 || lines.size() < row0 + static_cast<std::size_t>(height)) {
    return InvalidArgument("movingai grid: needs height, width, map and that many rows");
  }
  if (static_cast<double>(width) * height * subdivide * subdivide > 1e8) {
    return InvalidArgument("movingai grid: too many cells");
  }
  OccupancyGrid grid(width * subdivide, height * subdivide, tile / subdivide);
  for (int row = 0; row < height; ++row) {
    const std::string_view line = lines[row0 + static_cast<std::size_t>(row)];
    if (line.size() < static_cast<std::size_t>(width)) {
      return InvalidArgument("movingai grid: row " + std::to_string(row + 1) + " is shorter than the width");
    }
    for (int col = 0; col < width; ++col) {
      const char c = line[static_cast<std::size_t>(col)];
      if (c != '@' && c != 'T' && c != 'O' && c != 'W') continue;
      const int ty = height - 1 - row;  // y up
      for (int dy = 0; dy < subdivide; ++dy) {
        for (int dx = 0; dx < subdivide; ++dx) grid.Set(col * subdivide + dx, ty * subdivide + dy, true);
      }
    }
  }
  grid.ComputeClearance();
  return grid;
}

int OccupancyGrid::CellX(double x) const {
  return static_cast<int>(std::floor((x - origin_.x()) / resolution_));
}
int OccupancyGrid::CellY(double y) const {
  return static_cast<int>(std::floor((y - origin_.y()) / resolution_));
}

void OccupancyGrid::Set(int ix, int iy, bool occupied) {
  if (!InBounds(ix, iy)) return;
  cells_[static_cast<std::size_t>(iy) * width_ + ix] = occupied ? 1 : 0;
  clearance_.clear();
}

void OccupancyGrid::SetRect(const Eigen::Vector2d& min, const Eigen::Vector2d& max, bool occupied) {
  constexpr double kHair = 1e-9;
  const int x0 = std::max(0, CellX(min.x() + kHair));
  const int y0 = std::max(0, CellY(min.y() + kHair));
  const int x1 = std::min(width_ - 1, CellX(max.x() - kHair));
  const int y1 = std::min(height_ - 1, CellY(max.y() - kHair));
  for (int iy = y0; iy <= y1; ++iy) {
    for (int ix = x0; ix <= x1; ++ix) Set(ix, iy, occupied);
  }
}

void OccupancyGrid::ComputeClearance() {
  const std::size_t n = cells_.size();
  clearance_.assign(n, 0.0);
  // Distance from each free cell's centre to the grid's edge, then a Dijkstra sweep from the
  // occupied cells that carries each cell's nearest site (8-connected).
  std::vector<int> site(n, -1);
  std::vector<double> best(n, std::numeric_limits<double>::infinity());
  using Item = std::tuple<double, int, int>;  // distance, cell, site
  std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
  for (int i = 0; i < static_cast<int>(n); ++i) {
    if (cells_[i] != 0) {
      best[i] = 0.0;
      site[i] = i;
      open.emplace(0.0, i, i);
    }
  }
  auto distance = [this](int a, int b) {
    return resolution_ * std::hypot(a % width_ - b % width_, a / width_ - b / width_);
  };
  while (!open.empty()) {
    const auto [d, cell, s] = open.top();
    open.pop();
    if (d > best[cell] || site[cell] != s) continue;
    const int cx = cell % width_;
    const int cy = cell / width_;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if ((dx == 0 && dy == 0) || !InBounds(cx + dx, cy + dy)) continue;
        const int next = (cy + dy) * width_ + cx + dx;
        const double nd = distance(next, s);
        if (nd < best[next]) {
          best[next] = nd;
          site[next] = s;
          open.emplace(nd, next, s);
        }
      }
    }
  }
  for (int i = 0; i < static_cast<int>(n); ++i) {
    if (cells_[i] != 0) continue;
    const int ix = i % width_;
    const int iy = i / width_;
    const double edge = resolution_ * std::min({ix + 0.5, iy + 0.5, width_ - ix - 0.5, height_ - iy - 0.5});
    clearance_[i] = std::min(edge, best[i]);
  }
}

}  // namespace dispatch::engine
