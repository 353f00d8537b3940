// Small warehouse maps drawn as text for the time-window tests: '.' a lane cell, '@' a
// blocked one; cells 1 m apart, adjacent free cells joined by bidirectional single lanes.
// Points are named "r<row>c<col>", row 0 at the top (y = -row).
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/map/map_builder.h"
#include "engine/routing/route_table.h"

namespace dispatch::engine::testing_grid {

inline std::string CellName(int r, int c) { return "r" + std::to_string(r) + "c" + std::to_string(c); }

inline std::shared_ptr<const WarehouseMap> GridMap(const std::vector<std::string>& rows) {
  MapBuilder b("grid");
  const int h = static_cast<int>(rows.size()), w = static_cast<int>(rows.front().size());
  b.SetFloor({-1.0, -h}, {static_cast<double>(w), 1.0});
  b.AddRectZone("all", {-1.0, -h}, {static_cast<double>(w), 1.0});
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < w; ++c) {
      if (rows[r][c] == '.') b.AddPoint(CellName(r, c), {static_cast<double>(c), -static_cast<double>(r)}, PointKind::kLane);
    }
  }
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < w; ++c) {
      if (rows[r][c] != '.') continue;
      if (c + 1 < w && rows[r][c + 1] == '.') b.AddPath(CellName(r, c), CellName(r, c + 1), std::nullopt, 0.0, true);
      if (r + 1 < h && rows[r + 1][c] == '.') b.AddPath(CellName(r, c), CellName(r + 1, c), std::nullopt, 0.0, true);
    }
  }
  auto map = b.Build();
  if (!map.ok()) throw std::runtime_error(map.error().message);
  return std::make_shared<const WarehouseMap>(std::move(map).value());
}

inline std::unique_ptr<RouteTable> Routes(const std::shared_ptr<const WarehouseMap>& map, double speed = 1.0) {
  RouteTableOptions options;
  options.speed = speed;
  auto table = MakeRouteTable(map, options);
  if (!table.ok()) throw std::runtime_error(table.error().message);
  return std::move(table).value();
}

inline PointId At(const WarehouseMap& map, int r, int c) { return *map.FindPoint(CellName(r, c)); }

}  // namespace dispatch::engine::testing_grid
