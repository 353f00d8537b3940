// MemoryTrim: gives the free memory of every malloc arena back to the system now and then
// (issue 15 §3b). dispatchd's gRPC, HTTP and worker threads each allocate from their own glibc
// arena; what a thread frees stays mapped in its arena for its next request, so the resident
// set grew with the orders ever served although the live data did not (README "Memory soak").
// malloc_trim(0) releases the arenas' free pages (glibc >= 2.8; elsewhere a no-op).
//
// Not thread-safe: one owner (the dispatcher's loop) ticks it.
#pragma once

#include <chrono>

namespace dispatch::server {

class MemoryTrim {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr std::chrono::seconds kEvery{10};

  // Trims when kEvery has passed since the last trim; true when it trimmed.
  bool Tick(Clock::time_point wall);

 private:
  Clock::time_point next_{};
};

}  // namespace dispatch::server
