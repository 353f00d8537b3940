// The entry point every harness here defines (libFuzzer's): one input, return 0. Built two
// ways (fuzz/CMakeLists.txt): with clang's -fsanitize=fuzzer into a fuzzer (deploy/fuzz.sh),
// and with replay_main.cpp into a test that runs the saved corpus and every crash found
// (regression tests, in the README test command).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);
// Optional: runs once before the first input (a harness's fixed setup).
extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) __attribute__((weak));

namespace dispatch::fuzz {

inline std::string_view Text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

}  // namespace dispatch::fuzz
