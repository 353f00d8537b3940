#include "engine/motion/free_space_grid.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace dispatch::engine {

Result<OccupancyGrid> FreeSpaceGrid(const WarehouseMap& map, std::size_t region, double resolution) {
  if (region >= map.free_spaces().size()) {
    return NotFound("free space grid: the map has " + std::to_string(map.free_spaces().size()) +
                    " free spaces, no index " + std::to_string(region));
  }
  if (!(resolution > 0.0) || !std::isfinite(resolution)) {
    return InvalidArgument("free space grid: resolution must be > 0 metres");
  }
  const FreeSpace& space = map.free_spaces()[region];
  Eigen::Vector2d lo = space.polygon.front(), hi = space.polygon.front();
  for (const Eigen::Vector2d& v : space.polygon) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  const double w = std::ceil((hi.x() - lo.x()) / resolution - 1e-9);
  const double h = std::ceil((hi.y() - lo.y()) / resolution - 1e-9);
  if (w * h > 1e8) {
    return InvalidArgument("free space grid: '" + space.name + "' at " + std::to_string(resolution) +
                           " m cells is over 10^8 cells");
  }
  OccupancyGrid grid(std::max(1, static_cast<int>(w)), std::max(1, static_cast<int>(h)), resolution, lo);
  for (int iy = 0; iy < grid.height(); ++iy) {
    for (int ix = 0; ix < grid.width(); ++ix) {
      const Eigen::Vector2d centre = lo + resolution * Eigen::Vector2d(ix + 0.5, iy + 0.5);
      if (!space.Contains(centre)) grid.Set(ix, iy, true);
    }
  }
  for (const Shelf& shelf : map.shelves()) grid.SetRect(shelf.min, shelf.max, true);
  grid.ComputeClearance();
  return grid;
}

}  // namespace dispatch::engine
