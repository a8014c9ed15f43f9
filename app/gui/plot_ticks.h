// Axis ticks of the energy plot (GL-free): steps on a linear x axis, the energy on a log10 y
// axis.
#pragma once

#include <string>
#include <vector>

namespace qs::app {

struct AxisTick {
  double value = 0;
  std::string label;
};

//! Short label of a tick value: "0.5", "120", "2e-05" (at most 3 significant digits).
std::string tick_label(double value);

//! Integer ticks of [first, last] at steps of 1, 2 or 5 times a power of ten, at most
//! \p max_ticks of them (at least the two ends when first < last).
std::vector<AxisTick> step_ticks(int first, int last, int max_ticks);

//! Ticks of a log10 axis over [lo, hi] (both > 0, lo <= hi): the powers of ten inside, with
//! 2 and 5 times them when the range spans fewer than three decades, and evenly spaced values
//! ("nice" linear steps) when it spans less than one. Always at least two ticks (the ends when
//! nothing nicer fits). Empty when the range is not positive and finite.
std::vector<AxisTick> log_ticks(double lo, double hi);

}  // namespace qs::app
