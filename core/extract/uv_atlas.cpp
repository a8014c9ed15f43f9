#include "core/extract/uv_atlas.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "core/base/errors.h"

namespace qs {

namespace {

// Shelf packing at scale s: cell k (rectangle plus gutter g) of the sizes in `order` at
// corner[k]. Rows of cells left to right, a new shelf above the tallest cell of the last one
// when the next cell would cross u = 1. False when the shelves do not fit into [0,1]².
bool shelf_pack(const std::vector<std::array<double, 2>>& sizes, const std::vector<size_t>& order,
                double s, double g, std::vector<std::array<double, 2>>& corner) {
  corner.assign(sizes.size(), {0.0, 0.0});
  double x = 0, y = 0, shelf = 0;
  for (size_t k : order) {
    const double cw = s * sizes[k][0] + g, ch = s * sizes[k][1] + g;
    if (cw > 1) return false;
    if (x > 0 && x + cw > 1) {
      y += shelf;
      x = 0;
      shelf = 0;
    }
    corner[k] = {x, y};
    x += cw;
    shelf = std::max(shelf, ch);
  }
  return y + shelf <= 1;
}

}  // namespace

std::vector<UvRect> uv_atlas(const std::vector<std::array<double, 2>>& sizes,
                             const UvAtlasOptions& options) {
  if (!(std::isfinite(options.gutter) && options.gutter >= 0))
    throw InvalidInputError("uv atlas: the gutter must be a finite number >= 0 (got " +
                            std::to_string(options.gutter) + ")");
  for (size_t k = 0; k < sizes.size(); ++k)
    for (double x : sizes[k])
      if (!(std::isfinite(x) && x > 0))
        throw InvalidInputError("uv atlas: patch " + std::to_string(k) +
                                " has a non-positive or non-finite size");
  std::vector<UvRect> rects(sizes.size());
  if (options.layout == UvAtlasLayout::kPerPatch || sizes.empty()) return rects;

  const double n = static_cast<double>(sizes.size());
  // With this cap, the cells at scale 0 fill at most half of the atlas's height.
  const double g = std::min(options.gutter, 0.5 / std::ceil(std::sqrt(n)));
  std::vector<size_t> order(sizes.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return sizes[a][1] != sizes[b][1] ? sizes[a][1] > sizes[b][1] : sizes[a][0] > sizes[b][0];
  });
  double area = 0, max_w = 0, max_h = 0;
  for (const auto& s : sizes) {
    area += s[0] * s[1];
    max_w = std::max(max_w, s[0]);
    max_h = std::max(max_h, s[1]);
  }
  // No scale above hi fits: the rectangles' area, the widest and the tallest one.
  const double hi_bound = std::min({1 / std::sqrt(area), (1 - g) / max_w, (1 - g) / max_h});
  std::vector<std::array<double, 2>> corner;
  double lo = 0, hi = hi_bound;
  if (shelf_pack(sizes, order, hi, g, corner)) {
    lo = hi;
  } else {
    // lo fits (scale 0 does, by the gutter's cap), hi does not.
    for (int it = 0; it < 100 && hi - lo > 1e-15 * hi_bound; ++it) {
      const double mid = 0.5 * (lo + hi);
      (shelf_pack(sizes, order, mid, g, corner) ? lo : hi) = mid;
    }
  }
  shelf_pack(sizes, order, lo, g, corner);
  for (size_t k = 0; k < sizes.size(); ++k) {
    UvRect& r = rects[k];
    r.u0 = corner[k][0] + 0.5 * g;
    r.v0 = corner[k][1] + 0.5 * g;
    r.u1 = r.u0 + lo * sizes[k][0];
    r.v1 = r.v0 + lo * sizes[k][1];
  }
  return rects;
}

}  // namespace qs
