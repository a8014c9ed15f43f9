// Issues #4 and #5 on fertility.obj (genus 4, 27954 faces): the whole optimization (descent,
// hop polish, fold-over removal) embeds a layout on it. The layout is the simplified voxel-cage
// layout (test::fertility_simplified_cage_options, generated from ../shared; nothing derived
// from the model is shipped): with its imported node positions the parameterization folds and
// is not structurally equivalent (fertility_test.cpp). About two minutes in a Release build, so
// the sanitizer CI leaves it out (label "slow", tests/CMakeLists.txt).
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "core/layout/cage.h"
#include "core/layout/validate.h"
#include "core/mesh/mesh_io.h"
#include "core/nodeopt/optimizer.h"
#include "core/pipeline/pipeline.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

TEST(FertilityOptimize, SimplifiedCageLayoutEmbedsAfterNodeOptimization) {
  const std::string dir = test::shared_meshes_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/data/meshes is absent (fertility.obj test)";
  const TriMesh mesh = load_mesh(dir + "/fertility.obj");
  const CageResult cage = cage_layout(mesh, test::fertility_simplified_cage_options());
  ASSERT_TRUE(cage.simplified);
  ASSERT_TRUE(validate_layout(mesh, cage.layout).valid());
  const size_t patches = build_topology(mesh, cage.layout).patches.size();

  const NodeOptResult r = optimize_nodes(mesh, cage.layout, PipelineOptions{}, NodeOptOptions{});
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

}  // namespace
}  // namespace qs
