// A parameterised warehouse grid floor for simulations and benchmarks (issue 4 §5: "a large
// generated floor, e.g. 20 x 20 shelves"), in the style of imported MovingAI floors: cells
// 1 m apart, every pair of adjacent free cells one bidirectional single lane (Wang2019).
//
// Layout (cells; x = column, y = row, y up):
//   `border` free columns left and right of a block of shelf_rows x shelf_cols shelves
//   (`border_y` free rows above and below it; 0: `border` as well); each
//   shelf is shelf_w x shelf_h blocked cells; shelves are `aisle` cells apart both ways.
//   Pick points: the aisle cell just north and just south of each shelf's middle column
//   (2 per shelf). Drop points: every `drop_every`-th cell of the outermost left and right
//   columns. Zones: square tiles of `zone_cells` cells. No parking stations and no
//   intersections: on a grid every cell is a potential conflict point (the traffic
//   controller's business); robots start on lane cells (sim/fleet_placement.h).
// With aisle >= 2 no one-cell corridors exist, so robots can pass each other everywhere.
// Errors: sizes < 1 (aisle, border >= 1; border_y >= 0). Pure function; thread-safe.
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
  int border_y = 0;  // 0: border
  int drop_every = 4;
  int zone_cells = 10;
};

Result<WarehouseMap> BuildGridFloor(const GridFloorOptions& options = {});

// Seed 004 §4's floor (map source "wang2019"): a 40 x 30 grid of 1 m cells, 7 x 6 shelves of
// 4 x 2 cells, 2-cell aisles, 3 free columns left and right, 2 free rows above and below; a
// pick point north and south of each shelf, a drop (picking station) every 4th cell of the
// outer columns. The seed's Fig. 1 shows shelves, picking stations and lanes on a 40 x 30
// grid; its exact layout is not in the text. Named "wang2019".
Result<WarehouseMap> BuildWang2019Floor();

}  // namespace dispatch::engine
