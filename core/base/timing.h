// Wall-clock timing helper shared by the stages and the command line.
#pragma once

#include <chrono>

namespace qs {

//! Seconds elapsed since \p t0 (steady clock).
inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace qs
