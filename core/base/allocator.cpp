#include "core/base/allocator.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <thread>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace qs {

int kept_memory_arena_limit() {
  return std::max(2, static_cast<int>(std::thread::hardware_concurrency()));
}

bool keep_freed_memory() {
#if defined(__GLIBC__)
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (tunables && std::strstr(tunables, "glibc.malloc.")) return false;
  constexpr int kMmapThreshold = 32 << 20;  // glibc's maximum (HEAP_MAX_SIZE / 2 on 64 bit)
  constexpr int kTrimThreshold = 1 << 30;
  constexpr int kTopPad = 256 << 20;
  bool ok = mallopt(M_MMAP_THRESHOLD, kMmapThreshold) == 1;
  ok = (mallopt(M_TRIM_THRESHOLD, kTrimThreshold) == 1) && ok;
  ok = (mallopt(M_TOP_PAD, kTopPad) == 1) && ok;
  ok = (mallopt(M_ARENA_MAX, kept_memory_arena_limit()) == 1) && ok;
  return ok;
#else
  return false;
#endif
}

}  // namespace qs
