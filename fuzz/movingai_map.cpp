// The MovingAI .map reader (engine/io/movingai_map.h): any text gives a map or an error.
#include "engine/io/movingai_map.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  (void)dispatch::engine::ParseMovingAiMap(dispatch::fuzz::Text(data, size), "fuzz");
  return 0;
}
