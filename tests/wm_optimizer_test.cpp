// Node optimization on a working mesh (core/nodeopt/wm_optimizer.h): nodes move to exact surface
// points through their own vertices, the input surface never changes, and the result is the
// lowest-E fold-free structurally equivalent state.
#include "core/nodeopt/wm_optimizer.h"

#include <gtest/gtest.h>

#include <cstdio>

#include "core/layout/embed.h"
#include "core/layout/validate.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

MeshLayout embedded(const TriMesh& mesh, const Layout& layout) {
  EmbeddedLayout e = embed_layout(std::make_shared<const TriMesh>(mesh), layout);
  return MeshLayout{*e.mesh, e.layout};
}

void expect_exact_surface(const WorkingMesh& w) {
  EXPECT_LE(w.max_origin_error(), 1e-12);
  for (int v = 0; v < w.input_vertices(); ++v)
    ASSERT_EQ(w.mesh().point(OpenMesh::VertexHandle(v)),
              w.input().point(OpenMesh::VertexHandle(v)));
}

TEST(WmOptimizer, BundledSketchEmbedsWithExactNodeMoves) {
  const auto ex = test::ellipsoid_example();
  const WmResult r = optimize_working_layout(embedded(ex.mesh, ex.layout), PipelineOptions{});
  std::printf(
      "[stat] example: E %.6g -> %.6g (%s), fold-overs %d -> %d, %d steps (%d accepted), "
      "working mesh %.3fx, %.1f s\n",
      r.E_init, r.E_final, r.chosen.c_str(), r.foldovers_init, r.foldovers_final, r.steps,
      r.accepted, r.state->mesh.growth(), r.time_s);
  EXPECT_EQ(r.foldovers_final, 0);
  ASSERT_TRUE(r.pipeline);
  EXPECT_TRUE(r.pipeline->extract().structurally_equivalent);
  EXPECT_LT(r.E_final, 0.5 * r.E_init);
  expect_exact_surface(r.state->mesh);
  const ValidationResult v = validate_layout(r.state->mesh.mesh(), r.state->layout);
  for (const auto& issue : v.issues)
    if (issue.severity == IssueSeverity::Error) ADD_FAILURE() << format_issue(issue);
  EXPECT_LT(r.state->mesh.growth(), 1.5);
}

}  // namespace
}  // namespace qs
