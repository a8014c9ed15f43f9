// Texture atlas packing of the quad mesh's patches (quads.obj, `--atlas packed`).
#include "core/extract/uv_atlas.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "core/base/errors.h"

namespace qs {
namespace {

using Sizes = std::vector<std::array<double, 2>>;

// Packed-atlas properties for sizes and options: rectangles inside [0,1]² with half the gutter
// to the border, extents s·(w, h) with one s > 0, any two at least `gap` apart.
void expect_packed(const Sizes& sizes, const std::vector<UvRect>& rects, double gap) {
  ASSERT_EQ(rects.size(), sizes.size());
  const double s = (rects[0].u1 - rects[0].u0) / sizes[0][0];
  ASSERT_GT(s, 0);
  for (size_t k = 0; k < rects.size(); ++k) {
    const UvRect& r = rects[k];
    EXPECT_GE(std::min(r.u0, r.v0), 0.5 * gap - 1e-15) << k;
    EXPECT_LE(std::max(r.u1, r.v1), 1 - 0.5 * gap + 1e-15) << k;
    EXPECT_NEAR((r.u1 - r.u0) / sizes[k][0], s, 1e-12 * s) << k;
    EXPECT_NEAR((r.v1 - r.v0) / sizes[k][1], s, 1e-12 * s) << k;
  }
  int close = 0;
  for (size_t i = 0; i < rects.size(); ++i)
    for (size_t j = 0; j < i; ++j) {
      const UvRect &a = rects[i], &b = rects[j];
      close += std::max({b.u0 - a.u1, a.u0 - b.u1, b.v0 - a.v1, a.v0 - b.v1}) < gap - 1e-15;
    }
  EXPECT_EQ(close, 0) << "rectangle pairs closer than the gutter";
}

double filled(const std::vector<UvRect>& rects) {
  double area = 0;
  for (const auto& r : rects) area += (r.u1 - r.u0) * (r.v1 - r.v0);
  return area;
}

TEST(UvAtlas, PerPatchIsTheUnitSquare) {
  const auto rects = uv_atlas({{2, 1}, {0.5, 3}}, {});
  for (const auto& r : rects) {
    EXPECT_EQ(r.u0, 0);
    EXPECT_EQ(r.v0, 0);
    EXPECT_EQ(r.u1, 1);
    EXPECT_EQ(r.v1, 1);
  }
}

TEST(UvAtlas, ManyRandomPatchesPackWithoutOverlap) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> len(0.05, 3.0);
  Sizes sizes(300);
  for (auto& s : sizes) s = {len(rng), len(rng)};
  UvAtlasOptions opt;
  opt.layout = UvAtlasLayout::kPacked;
  const auto rects = uv_atlas(sizes, opt);
  expect_packed(sizes, rects, opt.gutter);
  EXPECT_GT(filled(rects), 0.4);
}

TEST(UvAtlas, ExtremeAspectRatiosFit) {
  const Sizes sizes = {{100, 1}, {1, 100}, {1, 1}, {0.01, 0.01}};
  UvAtlasOptions opt;
  opt.layout = UvAtlasLayout::kPacked;
  const auto rects = uv_atlas(sizes, opt);
  expect_packed(sizes, rects, opt.gutter);
  // A single patch fills the atlas up to the border gutter along its longer side.
  const auto one = uv_atlas({{2, 1}}, opt);
  expect_packed({{2, 1}}, one, opt.gutter);
  EXPECT_NEAR(one[0].u1 - one[0].u0, 1 - opt.gutter, 1e-12);
}

TEST(UvAtlas, GutterShrinksForManyPatches) {
  // 10000 patches cannot all be 1/256 apart: the gutter becomes 1/(2·100) and all still fit.
  Sizes sizes(10000, {1.0, 1.0});
  UvAtlasOptions opt;
  opt.layout = UvAtlasLayout::kPacked;
  opt.gutter = 0.01;
  const auto rects = uv_atlas(sizes, opt);
  expect_packed(sizes, rects, 0.005);
  EXPECT_GT(rects[0].u1 - rects[0].u0, 0);
}

TEST(UvAtlas, InvalidInputIsRefused) {
  UvAtlasOptions opt;
  opt.layout = UvAtlasLayout::kPacked;
  EXPECT_THROW(uv_atlas({{1, 0}}, opt), InvalidInputError);
  EXPECT_THROW(uv_atlas({{1, std::nan("")}}, opt), InvalidInputError);
  opt.gutter = -0.1;
  EXPECT_THROW(uv_atlas({{1, 1}}, opt), InvalidInputError);
  opt.gutter = std::numeric_limits<double>::infinity();
  EXPECT_THROW(uv_atlas({{1, 1}}, opt), InvalidInputError);
  EXPECT_TRUE(uv_atlas({}, UvAtlasOptions{UvAtlasLayout::kPacked}).empty());
}

}  // namespace
}  // namespace qs
