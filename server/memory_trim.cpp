#include "server/memory_trim.h"

#include <cstdlib>  // defines __GLIBC__ on glibc

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace dispatch::server {

bool MemoryTrim::Tick(Clock::time_point wall) {
  if (wall < next_) return false;
  next_ = wall + kEvery;
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
  return true;
}

}  // namespace dispatch::server
