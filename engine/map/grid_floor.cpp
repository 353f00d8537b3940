#include "engine/map/grid_floor.h"

#include <algorithm>
#include <string>
#include <vector>

#include "engine/map/map_builder.h"

namespace dispatch::engine {

namespace {

Result<WarehouseMap> Build(const GridFloorOptions& o, const std::string& map_name) {
  if (o.shelf_rows < 1 || o.shelf_cols < 1 || o.shelf_w < 1 || o.shelf_h < 1 || o.aisle < 1 ||
      o.border < 1 || o.border_y < 0 || o.drop_every < 1 || o.zone_cells < 1) {
    return InvalidArgument("grid floor: every size must be >= 1");
  }
  const int w = 2 * o.border + o.shelf_cols * o.shelf_w + (o.shelf_cols - 1) * o.aisle;
  const int border_y = o.border_y > 0 ? o.border_y : o.border;
  const int h = 2 * border_y + o.shelf_rows * o.shelf_h + (o.shelf_rows - 1) * o.aisle;
  // Cell kinds: 0 blocked, 1 lane, 2 pick, 3 drop.
  std::vector<int> kind(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 1);
  auto at = [&](int x, int y) -> int& {
    return kind[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)];
  };
  for (int r = 0; r < o.shelf_rows; ++r) {
    for (int c = 0; c < o.shelf_cols; ++c) {
      const int x0 = o.border + c * (o.shelf_w + o.aisle);
      const int y0 = border_y + r * (o.shelf_h + o.aisle);
      for (int y = y0; y < y0 + o.shelf_h; ++y) {
        for (int x = x0; x < x0 + o.shelf_w; ++x) at(x, y) = 0;
      }
      const int mid = x0 + o.shelf_w / 2;
      at(mid, y0 - 1) = 2;
      at(mid, y0 + o.shelf_h) = 2;
    }
  }
  for (int y = 0; y < h; y += o.drop_every) {
    at(0, y) = 3;
    at(w - 1, y) = 3;
  }
  MapBuilder b(map_name);
  b.SetFloor({-0.5, -0.5}, {w - 0.5, h - 0.5});
  for (int ty = 0; ty * o.zone_cells < h; ++ty) {
    for (int tx = 0; tx * o.zone_cells < w; ++tx) {
      const double x0 = tx * o.zone_cells - 0.5, y0 = ty * o.zone_cells - 0.5;
      b.AddRectZone("t" + std::to_string(ty) + "_" + std::to_string(tx), {x0, y0},
                    {std::min(x0 + o.zone_cells, w - 0.5), std::min(y0 + o.zone_cells, h - 0.5)});
    }
  }
  auto name = [&](int x, int y) { return "c" + std::to_string(y * w + x); };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const int k = at(x, y);
      if (k == 0) continue;
      b.AddPoint(name(x, y), {x, y},
                 k == 2 ? PointKind::kPick : (k == 3 ? PointKind::kDrop : PointKind::kLane));
    }
  }
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (at(x, y) == 0) continue;
      if (x + 1 < w && at(x + 1, y) != 0) b.AddPath(name(x, y), name(x + 1, y), 1.0, 0.0, true);
      if (y + 1 < h && at(x, y + 1) != 0) b.AddPath(name(x, y), name(x, y + 1), 1.0, 0.0, true);
    }
  }
  for (int r = 0; r < o.shelf_rows; ++r) {
    for (int c = 0; c < o.shelf_cols; ++c) {
      const double x0 = o.border + c * (o.shelf_w + o.aisle) - 0.5;
      const double y0 = border_y + r * (o.shelf_h + o.aisle) - 0.5;
      b.AddShelf("S" + std::to_string(r + 1) + "_" + std::to_string(c + 1), {x0, y0},
                 {x0 + o.shelf_w, y0 + o.shelf_h});
    }
  }
  return b.Build();
}

}  // namespace

Result<WarehouseMap> BuildGridFloor(const GridFloorOptions& o) {
  return Build(o, "grid_" + std::to_string(o.shelf_rows) + "x" + std::to_string(o.shelf_cols));
}

Result<WarehouseMap> BuildWang2019Floor() {
  GridFloorOptions o;
  o.shelf_rows = 7;
  o.shelf_cols = 6;
  o.border = 3;
  o.border_y = 2;
  return Build(o, "wang2019");
}

}  // namespace dispatch::engine
