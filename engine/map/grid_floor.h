// A parameterised warehouse grid floor for simulations and benchmarks (issue 4 §5: "a large
// generated floor, e.g. 20 x 20 shelves"), in the style of imported MovingAI floors: cells
// 1 m apart, every pair of adjacent free cells one bidirectional single lane (Wang2019).
//
// Layout (cells; x = column, y = row, y up):
//   a ring of `border` free cells around a block of shelf_rows x shelf_cols shelves; each
//   shelf is shelf_w x shelf_h blocked cells; shelves are `aisle` cells apart both ways.
//   Pick points: the aisle cell just north and just south of each shelf's middle column
//   (2 per shelf). Drop points: every `drop_every`-th cell of the outermost left and right
//   columns. Zones: square tiles of `zone_cells` cells. No parking stations and no
//   intersections: on a grid every cell is a potential conflict point (the traffic
//   controller's business); robots start on lane cells (sim/fleet_placement.h).
// With aisle >= 2 no one-cell corridors exist, so robots can pass each other everywhere.
// Errors: sizes < 1 (aisle, border >= 1). Pure function; thread-safe.
#pragma once

#include "engine/common/result.h"
#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

struct GridFloorOptions {
  int shelf_rows = 20;
  int shelf_cols = 20;
  int shelf_w = 4;
  int shelf_h = 2;
  int aisle = 2;
  int border = 2;
  int drop_every = 4;
  int zone_cells = 10;
};

Result<WarehouseMap> BuildGridFloor(const GridFloorOptions& options = {});

}  // namespace dispatch::engine
