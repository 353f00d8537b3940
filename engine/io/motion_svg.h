// SVG rendering of 4WIS motion paths for humans (issue 17 §3): the occupancy grid (occupied
// cells dark, merged into one rectangle per run of a row), and for each path its centre line
// and the robot's footprint rectangle every `footprint_every` metres along it (a spin counts
// as angle * spin_radius metres; the first and last poses are always drawn), in the path's
// colour, with a legend. The y axis points up as on the floor plan (SVG's y is flipped).
// Elements carry classes for tools and tests: "grid-cell", "path", "footprint", "legend".
// Thread safety: a pure function of its arguments; safe to call concurrently.
#pragma once

#include <string>
#include <vector>

#include "engine/motion/footprint.h"
#include "engine/motion/motion_path.h"
#include "engine/motion/occupancy_grid.h"

namespace dispatch::engine {

struct MotionSvgPath {
  std::string label;             // legend text
  std::string colour = "#1f77b4";
  MotionPath path;
  Footprint footprint;
};

struct MotionSvgOptions {
  double pixels_per_metre = 80.0;
  double footprint_every = 0.5;  // metres between drawn footprints
  double spin_radius = 0.3;      // metres per radian of spin, for the spacing above
  double margin_px = 10.0;
  std::string title;
};

std::string RenderMotionSvg(const OccupancyGrid& grid, const std::vector<MotionSvgPath>& paths,
                            const MotionSvgOptions& options = {});

}  // namespace dispatch::engine
