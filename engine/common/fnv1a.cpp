#include "engine/common/fnv1a.h"

#include <cstdio>

namespace dispatch::engine {

std::uint64_t Fnv1a64(std::string_view text, std::uint64_t basis) {
  std::uint64_t h = basis;
  for (unsigned char c : text) {
    h ^= c;
    h *= kFnv1a64Prime;
  }
  return h;
}

std::string Hex64(std::uint64_t value) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(value));
  return buf;
}

}  // namespace dispatch::engine
