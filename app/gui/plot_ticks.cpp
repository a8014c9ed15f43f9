#include "app/gui/plot_ticks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace qs::app {

namespace {

// The smallest of 1, 2, 5 times a power of ten that is at least \p x (> 0).
double nice_step(double x) {
  const double p = std::pow(10.0, std::floor(std::log10(x)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * p >= x * (1 - 1e-12)) return m * p;
  return 10.0 * p;
}

}  // namespace

std::string tick_label(double value) {
  char out[32];
  const double a = std::abs(value);
  if (a != 0.0 && (a < 1e-3 || a >= 1e5)) {
    const int exponent = int(std::floor(std::log10(a)));
    const double mantissa = value / std::pow(10.0, exponent);
    std::snprintf(out, sizeof(out), "%.3ge%d", mantissa, exponent);
  } else {
    std::snprintf(out, sizeof(out), "%.3g", value);
  }
  return out;
}

std::vector<AxisTick> step_ticks(int first, int last, int max_ticks) {
  std::vector<AxisTick> ticks;
  if (last < first) return ticks;
  if (last == first) return {{double(first), tick_label(first)}};
  max_ticks = std::max(2, max_ticks);
  const int step = std::max(1, int(nice_step(double(last - first) / double(max_ticks - 1))));
  // Multiples of the step, plus the first step when it is not one.
  const int start = (first + step - 1) / step * step;
  if (start != first) ticks.push_back({double(first), tick_label(first)});
  for (int v = start; v <= last; v += step) {
    if (!ticks.empty() && v - int(ticks.back().value) < step / 2) continue;
    ticks.push_back({double(v), tick_label(v)});
  }
  while (int(ticks.size()) > max_ticks) ticks.erase(ticks.begin() + 1);
  return ticks;
}

std::vector<AxisTick> log_ticks(double lo, double hi) {
  std::vector<AxisTick> ticks;
  if (!(lo > 0.0) || !std::isfinite(lo) || !std::isfinite(hi) || hi < lo) return ticks;
  const double decades = std::log10(hi / lo);
  const double eps = 1e-9;
  if (decades >= 1.0) {
    const int d0 = int(std::floor(std::log10(lo) + eps));
    const int d1 = int(std::floor(std::log10(hi) + eps));
    const int every = std::max(1, int(std::ceil((d1 - d0 + 1) / 6.0)));  // at most ~6 labels
    for (int d = d0; d <= d1; d += every)
      for (double m : {1.0, 2.0, 5.0}) {
        if (m > 1.0 && decades >= 3.0) break;
        const double v = m * std::pow(10.0, d);
        if (v >= lo * (1 - eps) && v <= hi * (1 + eps)) ticks.push_back({v, tick_label(v)});
      }
  } else if (hi > lo) {
    // Less than a decade: evenly spaced values read better than a single power of ten.
    const double step = nice_step((hi - lo) / 3.0);
    for (double v = std::ceil(lo / step - eps) * step; v <= hi * (1 + eps); v += step)
      if (v > 0.0) ticks.push_back({v, tick_label(v)});
  }
  if (ticks.size() < 2) {
    ticks = {{lo, tick_label(lo)}};
    if (hi > lo) ticks.push_back({hi, tick_label(hi)});
  }
  return ticks;
}

}  // namespace qs::app
