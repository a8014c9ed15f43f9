#include "core/pipeline/integer_sizes.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "core/base/errors.h"

namespace qs {

IntegerSizes round_arc_lengths(const std::vector<ArcLength>& relaxed, double quad_size) {
  if (!(quad_size > 0) || !std::isfinite(quad_size))
    throw InvalidInputError("integer sizes: the quad size must be a positive number, got " +
                            std::to_string(quad_size));
  for (const ArcLength& l : relaxed)
    if (!std::isfinite(l.length))
      throw InvalidInputError("integer sizes: arc " + std::to_string(l.arc_id) +
                              " has no finite parametric length");
  IntegerSizes out;
  out.quad_size = quad_size;
  out.lengths = relaxed;
  // Sort by |ℓ| and sweep groups of (chained) equal magnitudes.
  std::vector<size_t> order(relaxed.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return std::abs(relaxed[a].length) < std::abs(relaxed[b].length);
  });
  out.min_multiple = relaxed.empty() ? 0 : std::numeric_limits<int>::max();
  for (size_t begin = 0; begin < order.size();) {
    size_t end = begin + 1;
    double sum = std::abs(relaxed[order[begin]].length);
    while (end < order.size()) {
      const double prev = std::abs(relaxed[order[end - 1]].length);
      const double next = std::abs(relaxed[order[end]].length);
      if (next - prev > 1e-7 * std::max(next, quad_size)) break;
      sum += next;
      ++end;
    }
    const double mean = sum / static_cast<double>(end - begin);
    const double k = std::max(1.0, std::round(mean / quad_size));
    out.min_multiple = std::min(out.min_multiple, static_cast<int>(k));
    for (size_t i = begin; i < end; ++i) {
      ArcLength& l = out.lengths[order[i]];
      const double rounded = std::copysign(k * quad_size, l.length);
      out.max_change = std::max(out.max_change, std::abs(rounded - l.length));
      l.length = rounded;
    }
    begin = end;
  }
  return out;
}

}  // namespace qs
