// The built-in Chu2024 floor (seed 000 §4.1, Fig. 5/6; SPEC §2), reconstructed because the
// paper's figure is not in its text. See chu2024_floor.md beside this file for the layout,
// its dimensions and why each one was chosen.
//
// 5 rows x 6 columns of shelves with 3 pick slots each, two-way aisles with right-hand
// traffic (two opposite one-way lanes per aisle), a two-way ring road around the shelf block,
// 18 drop (receiving) points where the aisles leave the block, 18 parking stations of
// capacity 6 outside the ring (one robot each at start: R1..R18 in P1..P18), 6 zones.
// Every pick and drop coordinate of the seed's Tables 1 and 2 is a node.
//
// Pure function of its options; thread-safe.
#pragma once

#include <Eigen/Core>

#include <string>
#include <vector>

#include "engine/common/result.h"
#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

struct Chu2024FloorOptions {
  // Distance from an intersection's inner region to the approach point O_w where a robot
  // without a grant stops: robot radius 0.2 m + formation envelope margin (Chu2024 §3.3).
  double approach_distance = 0.6;
  // Robots per parking station (seed 000 §4.1: "can park 6 robots").
  int station_capacity = 6;
  // Pick positions off the lanes, each joined to the nearest lane point by a short
  // bidirectional single lane. The seed's tables pick at (14, 16.5) and (19, 16.5), half a
  // metre below the lane at y = 17, against shelf row 4's north face; by default every slot of
  // that face gets such a dock (18), so any table written like the paper's resolves.
  std::vector<Eigen::Vector2d> extra_pick_docks = Row4NorthFaceDocks();

  static std::vector<Eigen::Vector2d> Row4NorthFaceDocks();
};

Result<WarehouseMap> BuildChu2024Floor(const Chu2024FloorOptions& options = {});

// Station names P1..P18 in robot order: robot R<i> starts in station P<i>.
std::vector<std::string> Chu2024StationNames();

}  // namespace dispatch::engine
