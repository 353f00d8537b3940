// SVG rendering of a WarehouseMap for humans: floor, zones (translucent, labelled with their
// area S_p), free-space regions (narrow areas for four-wheel-steer robots, dashed green),
// shelves, lanes (one-way paths with arrowheads; bidirectional single lanes dashed
// and without arrows), intersections (inner region I_w highlighted, approach points O_w
// marked), points by kind, station capacities, optional labels and a legend. The y axis
// points up as on the floor plan (SVG's y is flipped).
//
// Maps with more than `detail_limit` points (e.g. a 38k-cell LoRR grid) use a compact style:
// geometry batched into one <path> per class in a flipped world-coordinate group, no arrows,
// no point labels; output stays a few MB at most.
//
// Thread safety: a pure function of its arguments; safe to call concurrently.
#pragma once

#include <cstddef>
#include <string>

#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

struct SvgOptions {
  double pixels_per_metre = 0.0;    // 0 = auto: the longer floor side becomes ~1200 px
  bool show_point_labels = true;    // point names (detailed style only)
  bool show_zone_labels = true;     // zone names and areas (up to 200 zones)
  bool show_legend = true;
  std::size_t detail_limit = 2000;  // above this many points: the compact style
  double margin_px = 20.0;
};

std::string RenderMapSvg(const WarehouseMap& map, const SvgOptions& options = {});

}  // namespace dispatch::engine
