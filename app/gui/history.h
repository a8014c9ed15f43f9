// Step-history scrubbing (GL-free, unit-tested in tests/worker_test.cpp): which streamed step
// the Pipeline panel shows when a new snapshot arrives.
#pragma once

#include <algorithm>

namespace qs::app {

//! Index of the shown step in a history of \p steps entries (-1 when empty): the newest one
//! when \p live, else \p current clamped to [0, steps - 1].
inline int scrub_index(int current, int steps, bool live) {
  if (steps <= 0) return -1;
  if (live) return steps - 1;
  return std::clamp(current, 0, steps - 1);
}

}  // namespace qs::app
