// Importer for MovingAI / League of Robot Runners `.map` grid files (SPEC §2 map source 3).
//
// Format: header lines "type octile", "height H", "width W", "map", then H rows of W
// characters. '.', 'G', 'S' and 'E' are free ('S' = pickup, imported as a pick point; 'E' =
// delivery/end, a drop point; '.' and 'G' are lane points); '@', 'T', 'O' and 'W' are blocked.
//
// Mapping (invariants of every imported map):
//  - one point per kept free cell, named "c<row*W+col>" (the LoRR cell id, so agents/tasks
//    files map to points by name), at x = col, y = H-1-row (metres, 1 m apart, y up);
//  - 4-connectivity: each pair of adjacent free cells is ONE Path with bidirectional=true
//    (a single lane, Wang2019), written from the lower to the higher cell id, length 1 m;
//  - floor = [-0.5, W-0.5] x [-0.5, H-0.5], so each cell is the unit square around its point;
//  - zones are square tiles of `tile_cells` cells named "t<tile_row>_<tile_col>" (tile rows
//    counted from the top of the text), clipped to the floor; only tiles that hold a kept
//    point are created;
//  - free cells outside the largest 4-connected component (ties: the one holding the lowest
//    cell id) are dropped and counted in MovingAiImportReport::dropped_cells, so every
//    service point reaches every other one;
//  - no intersections are declared: on a grid every cell is a potential conflict point, which
//    the traffic layer handles.
// Errors name the line (and column) of the file: "line 7: expected 32 characters, got 31".
//
// Thread safety: free functions without shared state; safe to call concurrently.
#pragma once

#include <string>
#include <string_view>

#include "engine/common/result.h"
#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

struct MovingAiImportOptions {
  int tile_cells = 10;     // zone tile edge, in cells (= metres); must be >= 1
  double max_speed = 0.0;  // max_speed of every lane; 0 = no limit of its own
};

struct MovingAiImportReport {
  int height = 0;
  int width = 0;
  int free_cells = 0;     // free characters in the file
  int dropped_cells = 0;  // free cells outside the largest 4-connected component
  int points = 0;         // = free_cells - dropped_cells
  int lanes = 0;          // bidirectional single-lane paths
  int zones = 0;
};

// Parses `.map` text into a map called `name`. `report` (optional) receives the counts.
Result<WarehouseMap> ParseMovingAiMap(std::string_view text, std::string name,
                                      const MovingAiImportOptions& options = {},
                                      MovingAiImportReport* report = nullptr);

// Reads a `.map` file; the map is named after the file's stem ("warehouse_large"). Errors are
// prefixed with the path; an unreadable file is kIoError.
Result<WarehouseMap> LoadMovingAiMapFile(const std::string& path,
                                         const MovingAiImportOptions& options = {},
                                         MovingAiImportReport* report = nullptr);

}  // namespace dispatch::engine
