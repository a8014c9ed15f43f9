// Issues #4 and #5 on fertility.obj (genus 4, 27954 faces): the whole optimization (descent,
// hop polish, fold-over removal) embeds a layout on it. The layout is the simplified voxel-cage
// layout (test::fertility_simplified_cage_options, generated from ../shared; nothing derived
// from the model is shipped): with its imported node positions the parameterization folds and
// is not structurally equivalent (fertility_test.cpp). The optimized layout, saved and read back
// on the original mesh, embeds with fixed nodes when the parameterization has orientation
// constraints (`optimize --no-node-opt --orientation`). The optimization runs once for both
// tests: 0.5–2 minutes in a Release build, so the sanitizer CI leaves them out (label "slow",
// tests/CMakeLists.txt).
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <string>

#include "core/import/cage.h"
#include "core/layout/layout_io.h"
#include "core/layout/validate.h"
#include "core/mesh/mesh_io.h"
#include "core/nodeopt/optimizer.h"
#include "core/pipeline/pipeline.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

struct Optimized {
  TriMesh mesh;  // fertility.obj as read
  CageResult cage;
  size_t patches = 0;
  NodeOptResult result;  // optimize_nodes with the defaults
};

// The simplified cage layout and its optimization, made once per test binary; nullptr without
// ../shared.
const Optimized* optimized() {
  static const std::unique_ptr<Optimized> data = []() -> std::unique_ptr<Optimized> {
    const std::string dir = test::shared_meshes_dir();
    if (dir.empty()) return nullptr;
    auto o = std::make_unique<Optimized>();
    o->mesh = test::load_mesh(dir + "/fertility.obj");
    o->cage = cage_layout(o->mesh, test::fertility_simplified_cage_options());
    o->patches = build_topology(o->mesh, o->cage.layout).patches.size();
    o->result = optimize_nodes(o->mesh, o->cage.layout, PipelineOptions{}, NodeOptOptions{});
    return o;
  }();
  return data.get();
}

#define QS_OPTIMIZED_OR_SKIP(name)                                                   \
  const Optimized* name = optimized();                                               \
  if (!name) GTEST_SKIP() << "../shared/data/meshes is absent (fertility.obj test)"; \
  ASSERT_TRUE(name->cage.simplified);                                                \
  ASSERT_TRUE(validate_layout(name->mesh, name->cage.layout).valid())

TEST(FertilityOptimize, SimplifiedCageLayoutEmbedsAfterNodeOptimization) {
  QS_OPTIMIZED_OR_SKIP(o);
  const size_t patches = o->patches;
  const NodeOptResult& r = o->result;
  EXPECT_GT(r.foldovers_init, 0) << "the cage layout's own node positions should fold";
  EXPECT_LT(r.E_final, r.E_init);
  EXPECT_EQ(r.foldovers_final, 0);
  EXPECT_TRUE(validate_layout(r.mesh, r.layout).valid());
  ASSERT_TRUE(r.pipeline);
  Pipeline& final_solve = *r.pipeline;
  const Extraction& ex = final_solve.extract();
  for (size_t i = 0; i < ex.problems.size() && i < 10; ++i) ADD_FAILURE() << ex.problems[i];
  EXPECT_TRUE(ex.structurally_equivalent);
  EXPECT_EQ(ex.bad_cones, 0);
  EXPECT_EQ(ex.patch_size.size(), patches);
  const test::EmbeddingCheck check = test::check_embedding(final_solve);
  EXPECT_LT(check.iso_violation, 1e-6) << "iso-line violation";
  EXPECT_LT(check.side_mismatch, 1e-6) << "opposite patch sides differ";
  EXPECT_GT(check.sides_checked, 0);
  const ParamMetrics m = final_solve.metrics();
  std::printf(
      "[stat] fertility simplified cage layout (%zu patches), optimize: E %.6g -> %.6g, "
      "fold-overs %d -> %d (descent) -> %d, %d steps, %d hops, E° %.2f deg, %.1f s\n",
      patches, r.E_init, r.E_final, r.foldovers_init, r.foldovers_descent, r.foldovers_final,
      r.steps, r.hops, m.E_angle_deg, r.time_s);
}

// Issue #4 (a layout on fertility.obj, parameterization without node optimization): the
// optimized layout as a user gets it (layout.json, nodes as surface points), read back on the
// original mesh — its nodes snap to the nearest vertices and the relocated vertices are back in
// place — and parameterized with fixed nodes and orientation constraints. The cage's own node
// positions cannot do this (the constrained QP is infeasible there); the optimized positions can.
TEST(FertilityOptimize, OptimizedLayoutEmbedsWithFixedNodesAndOrientationConstraints) {
  QS_OPTIMIZED_OR_SKIP(o);
  ASSERT_TRUE(o->result.pipeline);
  const std::string path = test::temp_dir("fertility_optimized") + "/optimized.layout.json";
  save_layout(o->result.pipeline->output_layout(), path, &o->result.mesh);
  const Layout layout = load_layout(path, o->mesh);
  ASSERT_TRUE(validate_layout(o->mesh, layout).valid());

  PipelineOptions options;
  options.param.orientation.enabled = true;  // optimize --no-node-opt --orientation
  Pipeline pipeline(o->mesh, layout, options);
  const Parameterization& param = pipeline.compute_parameterization();
  EXPECT_EQ(param.foldovers, 0);
  const Extraction& ex = pipeline.extract();
  for (size_t i = 0; i < ex.problems.size() && i < 10; ++i) ADD_FAILURE() << ex.problems[i];
  EXPECT_TRUE(ex.structurally_equivalent);
  EXPECT_EQ(ex.bad_cones, 0);
  EXPECT_EQ(ex.patch_size.size(), o->patches);
  const test::EmbeddingCheck check = test::check_embedding(pipeline);
  EXPECT_LT(check.iso_violation, 1e-6) << "iso-line violation";
  EXPECT_LT(check.side_mismatch, 1e-6) << "opposite patch sides differ";
  EXPECT_GT(check.sides_checked, 0);
  // The nodes stayed where the file put them.
  ASSERT_EQ(pipeline.layout().nodes.size(), layout.nodes.size());
  for (size_t n = 0; n < layout.nodes.size(); ++n)
    EXPECT_EQ(pipeline.layout().nodes[n].vertex, layout.nodes[n].vertex) << "node " << n;
  std::printf(
      "[stat] fertility optimized layout re-read, --no-node-opt --orientation: fold-overs %d -> "
      "%d (%s, %d rounds, %d constrained faces), E %.6g, E° %.2f deg\n",
      param.orientation.ran ? param.orientation.foldovers_before : param.foldovers, param.foldovers,
      param.orientation.ran ? "orientation constraints" : "none needed", param.orientation.rounds,
      param.orientation.constrained_faces, param.energy, pipeline.metrics().E_angle_deg);
}

}  // namespace
}  // namespace qs
