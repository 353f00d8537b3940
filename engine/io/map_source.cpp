#include "engine/io/map_source.h"

#include "engine/io/map_json.h"
#include "engine/io/movingai_map.h"
#include "engine/map/chu2024_floor.h"
#include "engine/map/grid_floor.h"

namespace dispatch::engine {

namespace {
bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}
}  // namespace

Result<WarehouseMap> LoadMapSource(const std::string& source) {
  if (source == "chu2024") return BuildChu2024Floor();
  if (source == "wang2019") return BuildWang2019Floor();
  if (EndsWith(source, ".json")) return LoadMapJsonFile(source);
  if (EndsWith(source, ".map")) return LoadMovingAiMapFile(source);
  return InvalidArgument("unknown map source '" + source +
                         "': expected 'chu2024', 'wang2019', a .json map file or a MovingAI .map file");
}

}  // namespace dispatch::engine
