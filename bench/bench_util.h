// Helpers shared by the bench executables (not tests).
#pragma once

#include <time.h>

#include <algorithm>
#include <vector>

namespace qs::bench {

//! CPU seconds used by the whole process so far (CLOCK_PROCESS_CPUTIME_ID): on a shared,
//! loaded machine the comparable measure, unlike wall time.
inline double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

//! Monotonic wall-clock seconds (CLOCK_MONOTONIC): what a user waits, threads overlapping.
inline double wall_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

//! Median (upper median for an even count; 0 for none).
inline double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace qs::bench
