// Quality metrics (algorithm.md §8): degenerate parametric images must not dominate E_confor.
#include "core/extract/metrics.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/field/curvature.h"
#include "fixtures.h"

namespace qs {
namespace {

// Corner values equal to the face's own 2D frame coordinates: an isometric parameterization.
std::vector<std::array<double, 2>> isometric_uv(const TriMesh& mesh, const GeometryCache& g) {
  std::vector<std::array<double, 2>> uv(3 * g.n_faces);
  for (int f = 0; f < g.n_faces; ++f) {
    const auto c = face_corners_2d(mesh, g, f);
    for (int k = 0; k < 3; ++k) uv[3 * f + k] = c[k];
  }
  return uv;
}

TEST(Metrics, IsometricMapIsConformal) {
  const auto in = test::disk_grid(4, 4, 2, 2);
  const GeometryCache g = build_geometry(in.mesh);
  const Curvature curv = compute_curvature(in.mesh, g);
  const ParamMetrics m = compute_metrics(in.mesh, g, curv, isometric_uv(in.mesh, g), 0.0);
  EXPECT_NEAR(m.E_confor, 2.0, 1e-9);
  EXPECT_EQ(m.foldovers, 0);
  EXPECT_EQ(m.degenerate, 0);
}

TEST(Metrics, CollapsedFacesAreCountedNotAveraged) {
  // The inspired_mesh case: boundary iso-line constraints put all three corners of an "ear"
  // face (two boundary edges on one arc) on one line, so σ2 is zero up to round-off and
  // σ1/σ2 reached 1e28. Collapse two faces exactly and one up to round-off.
  const auto in = test::disk_grid(4, 4, 2, 2);
  const GeometryCache g = build_geometry(in.mesh);
  const Curvature curv = compute_curvature(in.mesh, g);
  auto uv = isometric_uv(in.mesh, g);
  ASSERT_GE(g.n_faces, 3);
  for (int f : {0, 1}) {  // all corners on the segment u ∈ [0, 1], v = 0
    for (int k = 0; k < 3; ++k) uv[3 * f + k] = {0.5 * k, 0.0};
  }
  for (int k = 0; k < 3; ++k) uv[3 * 2 + k] = {0.5 * k, 1e-17 * k * k};
  const ParamMetrics m = compute_metrics(in.mesh, g, curv, uv, 0.0);
  EXPECT_EQ(m.degenerate, 3);
  EXPECT_GE(m.foldovers, 2);
  EXPECT_TRUE(std::isfinite(m.E_confor));
  EXPECT_NEAR(m.E_confor, 2.0, 1e-9);  // the remaining faces are isometric
}

TEST(Metrics, NonFiniteCornerValuesAreDegenerate) {
  const auto in = test::disk_grid(2, 2, 1, 1);
  const GeometryCache g = build_geometry(in.mesh);
  const Curvature curv = compute_curvature(in.mesh, g);
  auto uv = isometric_uv(in.mesh, g);
  uv[0] = {std::nan(""), 0.0};
  const ParamMetrics m = compute_metrics(in.mesh, g, curv, uv, 0.0);
  EXPECT_EQ(m.degenerate, 1);
  EXPECT_NEAR(m.E_confor, 2.0, 1e-9);
}

}  // namespace
}  // namespace qs
