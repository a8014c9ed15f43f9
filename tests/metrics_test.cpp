// Quality metrics (docs/design.md, "Metrics"): degenerate parametric images must not dominate
// E_confor.
#include "core/extract/metrics.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/field/cross_field.h"
#include "core/field/curvature.h"
#include "core/pipeline/pipeline.h"
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

// Pipeline::metrics takes E°'s curvature from the field solver when the field computed it at the
// same positions: the metrics are bit-identical to a fresh compute_curvature's, and after the
// vertices moved (the field's solve keeps its constraints and curvature) the fresh one is used.
TEST(Metrics, PipelineReusesTheFieldsCurvatureOnlyAtTheSamePositions) {
  auto e = test::cube_sphere(12, Vec3(1.3, 1, 0.75));
  Pipeline p(e.mesh, e.layout, PipelineOptions{});
  p.compute_parameterization();
  ASSERT_NE(p.field_solver(), nullptr);
  ASSERT_NE(p.field_solver()->curvature_at(p.mesh(), CurvatureOptions{}), nullptr)
      << "the field computed the curvature E° needs";
  auto expect_fresh = [](Pipeline& q) {
    const Parameterization& par = *q.parameterization();
    const ParamMetrics fresh =
        compute_metrics(q.mesh(), q.geometry(), compute_curvature(q.mesh(), q.geometry()),
                        par.corner_uv, par.energy);
    const ParamMetrics m = q.metrics();
    EXPECT_EQ(m.E_angle_deg, fresh.E_angle_deg);
    EXPECT_EQ(m.E_planar, fresh.E_planar);
    EXPECT_EQ(m.E_confor, fresh.E_confor);
    EXPECT_GT(m.E_angle_deg, 0.0);
  };
  expect_fresh(p);
  // Other options, or curvature constraints off: no reuse.
  CurvatureOptions other;
  other.rings = 3;
  EXPECT_EQ(p.field_solver()->curvature_at(p.mesh(), other), nullptr);
  PipelineOptions no_align;
  no_align.field.constraints.curvature = false;
  Pipeline q(e.mesh, e.layout, no_align);
  q.compute_parameterization();
  ASSERT_NE(q.field_solver(), nullptr);
  EXPECT_EQ(q.field_solver()->curvature_at(q.mesh(), CurvatureOptions{}), nullptr);
  expect_fresh(q);
  // Moved vertices: the field's curvature is of the old positions.
  TriMesh moved = p.mesh();
  for (int v = 0; v < 40; ++v) {
    const auto vh = moved.vertex_handle(v);
    moved.set_point(vh, moved.point(vh) * 1.02);
  }
  p.update_positions(moved);
  p.compute_parameterization();
  ASSERT_NE(p.field_solver(), nullptr);
  EXPECT_EQ(p.field_solver()->curvature_at(p.mesh(), CurvatureOptions{}), nullptr);
  expect_fresh(p);
}

}  // namespace
}  // namespace qs
