// The JSON map reader (engine/io/map_json.h): any text gives a map or an error, never a crash;
// a map it gives writes back to JSON that reads back.
#include <cstdlib>

#include "engine/io/map_json.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto map = dispatch::engine::ParseMapJson(dispatch::fuzz::Text(data, size));
  if (!map.ok()) return 0;
  auto again = dispatch::engine::ParseMapJson(dispatch::engine::WriteMapJson(*map));
  if (!again.ok() || again->point_count() != map->point_count()) std::abort();
  return 0;
}
