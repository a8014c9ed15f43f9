#include "core/base/allocator.h"

#include <sys/resource.h>

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <thread>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace qs {

std::size_t kept_memory_top_pad() {
  constexpr std::size_t kTopPad = std::size_t(256) << 20;
  std::size_t pad = kTopPad;
  // Under an address-space or data limit (ulimit -v / -d) the pad is reserved against the
  // limit at every growth of the heap: a run would hit the limit up to the pad earlier.
  for (const int resource : {RLIMIT_AS, RLIMIT_DATA}) {
    struct rlimit limit {};
    if (getrlimit(resource, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
      pad = std::min<std::size_t>(pad, static_cast<std::size_t>(limit.rlim_cur / 64));
  }
  return pad;
}

int kept_memory_arena_limit() {
  return std::max(2, static_cast<int>(std::thread::hardware_concurrency()));
}

bool keep_freed_memory() {
#if defined(__GLIBC__)
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (tunables && std::strstr(tunables, "glibc.malloc.")) return false;
  constexpr int kMmapThreshold = 32 << 20;  // glibc's maximum (HEAP_MAX_SIZE / 2 on 64 bit)
  constexpr int kTrimThreshold = 1 << 30;
  bool ok = mallopt(M_MMAP_THRESHOLD, kMmapThreshold) == 1;
  ok = (mallopt(M_TRIM_THRESHOLD, kTrimThreshold) == 1) && ok;
  ok = (mallopt(M_TOP_PAD, static_cast<int>(kept_memory_top_pad())) == 1) && ok;
  ok = (mallopt(M_ARENA_MAX, kept_memory_arena_limit()) == 1) && ok;
  return ok;
#else
  return false;
#endif
}

}  // namespace qs
