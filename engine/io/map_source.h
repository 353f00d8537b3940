// Resolves a map source given on a command line or in a config file:
//   "chu2024"        the built-in Chu2024 floor (engine/map/chu2024_floor.h)
//   "wang2019"       the built-in 40 x 30 grid of Wang2019 §4 (engine/map/grid_floor.h)
//   "<file>.json"    a map file in the JSON format of engine/io/map_format.md
//   "<file>.map"     a MovingAI grid (engine/io/movingai_map.h)
// Anything else is an InvalidArgument error that lists the accepted forms.
// Stateless; thread-safe.
#pragma once

#include <string>

#include "engine/common/result.h"
#include "engine/map/warehouse_map.h"

namespace dispatch::engine {

Result<WarehouseMap> LoadMapSource(const std::string& source);

}  // namespace dispatch::engine
