// Issues #3 and #4 on fertility.obj (genus 4, 27954 faces). The model has no licence statement,
// so neither it nor a layout derived from it is shipped: the layout is a voxel-cage layout
// (core/import/cage.h) generated here from ../shared, once per test binary. The tests skip when
// ../shared is absent.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "core/field/cross_field.h"
#include "core/import/cage.h"
#include "core/layout/validate.h"
#include "core/mesh/geometry.h"
#include "core/mesh/mesh_checks.h"
#include "core/mesh/mesh_io.h"
#include "core/pipeline/pipeline.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

struct Fertility {
  TriMesh mesh;
  CageResult cage;
  std::string error;  // why the layout could not be made
};

// The mesh and its cage layout, made once; nullptr without ../shared.
const Fertility* fertility() {
  static const std::unique_ptr<Fertility> data = []() -> std::unique_ptr<Fertility> {
    const std::string dir = test::shared_meshes_dir();
    if (dir.empty()) return nullptr;
    auto f = std::make_unique<Fertility>();
    f->mesh = load_mesh(dir + "/fertility.obj");
    try {
      f->cage = cage_layout(f->mesh, test::fertility_cage_options());
    } catch (const std::exception& e) {
      f->error = e.what();
    }
    return f;
  }();
  return data.get();
}

#define QS_FERTILITY_OR_SKIP(name)                                                   \
  const Fertility* name = fertility();                                               \
  if (!name) GTEST_SKIP() << "../shared/data/meshes is absent (fertility.obj test)"; \
  ASSERT_TRUE(name->error.empty()) << name->error

int euler(const TriMesh& m) {
  return static_cast<int>(m.n_vertices()) - static_cast<int>(m.n_edges()) +
         static_cast<int>(m.n_faces());
}

TEST(Fertility, CageLayoutIsValidWithTheMeshGenus) {
  QS_FERTILITY_OR_SKIP(f);
  MeshReport report;
  count_topology(f->mesh, report);
  ASSERT_EQ(report.genus, 4);
  EXPECT_EQ(f->cage.voxels.genus, 4);
  EXPECT_EQ(f->cage.voxels.components, 1);
  const ValidationResult validation = validate_layout(f->mesh, f->cage.layout);
  EXPECT_TRUE(validation.valid());
  for (const auto& issue : validation.issues) ADD_FAILURE() << format_issue(issue);
  const LayoutTopology topo = build_topology(f->mesh, f->cage.layout);
  // Σ(4 − valence) over the nodes = 4χ for a quad layout of a closed surface.
  int sum = 0;
  for (int v : topo.valence) sum += 4 - v;
  EXPECT_EQ(sum, 4 * euler(f->mesh));
  EXPECT_EQ(static_cast<int>(topo.patches.size()), f->cage.complex.num_patches);
  for (const auto& patch : topo.patches) EXPECT_EQ(patch.darts.size(), 4u);
  // A moderate layout: coarser than the cage, far from one patch per few triangles.
  EXPECT_LT(topo.patches.size(), f->cage.coarsen.patches_before);
  EXPECT_LT(topo.patches.size() * 20, f->mesh.n_faces());
  std::printf(
      "[stat] fertility cage layout: resolution %d (shift %.2f, split %dx), %d nodes, %zu "
      "patches (%d before coarsening)\n",
      f->cage.resolution, f->cage.shift, f->cage.refined, topo.num_nodes, topo.patches.size(),
      f->cage.coarsen.patches_before);
}

// CageOptions::simplify on fertility: the coarsened cage complex as a coarse quad mesh, its
// nearby irregular vertices cancelled, re-embedded. Resolution 34, unshifted (without simplify
// no grid at 34 transfers).
TEST(Fertility, SimplifiedCageLayoutHasFewerIrregularNodes) {
  QS_FERTILITY_OR_SKIP(f);
  const CageResult cage = cage_layout(f->mesh, test::fertility_simplified_cage_options());
  ASSERT_TRUE(cage.simplified);
  const ValidationResult validation = validate_layout(f->mesh, cage.layout);
  EXPECT_TRUE(validation.valid());
  for (const auto& issue : validation.issues) ADD_FAILURE() << format_issue(issue);
  const LayoutTopology topo = build_topology(f->mesh, cage.layout);
  int sum = 0, irregular = 0;
  for (int v : topo.valence) {
    sum += 4 - v;
    irregular += v != 4;
  }
  EXPECT_EQ(sum, 4 * euler(f->mesh));
  for (const auto& patch : topo.patches) EXPECT_EQ(patch.darts.size(), 4u);
  EXPECT_EQ(irregular, cage.simplify.irregular_after);
  int plain_irregular = 0;
  for (int v : build_topology(f->mesh, f->cage.layout).valence) plain_irregular += v != 4;
  EXPECT_LT(irregular, plain_irregular);
  Pipeline pipeline(f->mesh, cage.layout);
  const Parameterization& param = pipeline.compute_parameterization();
  const Extraction& ex = pipeline.extract();
  std::printf(
      "[stat] fertility simplified cage layout: %d nodes (%d irregular; plain layout %d), %zu "
      "patches; --no-node-opt: %d fold-overs, %d bad cones, E° %.2f deg, structurally "
      "equivalent %d\n",
      topo.num_nodes, irregular, plain_irregular, topo.patches.size(), param.foldovers,
      ex.bad_cones, pipeline.metrics().E_angle_deg, ex.structurally_equivalent ? 1 : 0);
}

// Issue #3: the field has exactly the layout's singularities, measured on the field alone, and
// they sum to χ = −6.
TEST(Fertility, FieldIndicesAreTheLayoutsAndSumToEuler) {
  QS_FERTILITY_OR_SKIP(f);
  const GeometryCache geometry = build_geometry(f->mesh);
  const LayoutTopology topo = build_topology(f->mesh, f->cage.layout);
  const CrossField field = compute_cross_field(f->mesh, geometry, f->cage.layout, topo);
  const test::FieldIndexCheck check =
      test::check_field_indices(f->mesh, geometry, f->cage.layout, topo, field.theta);
  for (const auto& e : check.examples) ADD_FAILURE() << e;
  EXPECT_EQ(check.wrong, 0) << check.spurious << " of them away from the nodes";
  ASSERT_EQ(euler(f->mesh), -6);
  EXPECT_EQ(check.sum, 4 * euler(f->mesh));  // quarter turns
  EXPECT_GT(check.irregular, 0);
  std::printf("[stat] fertility field: %d irregular nodes, index sum %d/4\n", check.irregular,
              check.sum);
}

// Issue #4: the embedding traced on the parameterization (--no-node-opt). Disabled: with the
// cage's own node positions the parameterization folds (664–2304 fold-overs, 237 nodes with a
// wrong cone angle), so the traced layout is not structurally equivalent; the simplified cage
// layout (above) folds less (504 aligned, 750 --no-align) but is not equivalent either. After node
// optimization the simplified layout embeds (fertility_optimize_test.cpp: 0 fold-overs,
// structurally equivalent); the plain one keeps about 600 fold-overs (65 wrongly winding nodes).
// The layout the optimization makes, read back on the original mesh, embeds with fixed nodes once
// the parameterization has orientation constraints (fertility_optimize_test.cpp); the cage's own
// positions stay infeasible for them. Run with --gtest_also_run_disabled_tests to see the numbers.
TEST(Fertility, DISABLED_ParameterizationEmbedsTheLayout) {
  QS_FERTILITY_OR_SKIP(f);
  Pipeline pipeline(f->mesh, f->cage.layout);
  const Parameterization& param = pipeline.compute_parameterization();
  const Extraction& ex = pipeline.extract();
  for (size_t i = 0; i < ex.problems.size() && i < 5; ++i) ADD_FAILURE() << ex.problems[i];
  EXPECT_TRUE(ex.structurally_equivalent);
  EXPECT_EQ(ex.patch_size.size(), pipeline.topology().patches.size());
  const test::EmbeddingCheck check = test::check_embedding(pipeline);
  EXPECT_LT(check.iso_violation, 1e-6) << "iso-line violation";
  EXPECT_LT(check.side_mismatch, 1e-6) << "opposite patch sides differ";
  EXPECT_GT(check.sides_checked, 0);
  std::printf(
      "[stat] fertility param: %d fold-overs, %d bad cones, iso violation %.3g, side "
      "mismatch %.3g\n",
      param.foldovers, ex.bad_cones, check.iso_violation, check.side_mismatch);
}

// Issue #4: E° of the aligned parameterization is lower than that of the --no-align baseline
// with the same layout — with split curvature clusters (CrossFieldOptions::max_cluster_faces,
// `--max-cluster-faces 10`). With whole clusters (the default) it is false on this layout
// (10 of the 12 constraint clusters are dropped as contradicting the layout); the default's
// numbers are printed.
TEST(Fertility, SplitClustersAlignmentLowersAngleError) {
  QS_FERTILITY_OR_SKIP(f);
  double angle[3] = {0, 0, 0};
  int folds[3] = {0, 0, 0};
  for (int run = 0; run < 3; ++run) {  // --no-align, aligned (whole clusters), aligned (split)
    PipelineOptions options;
    options.field.constraints.curvature = run != 0;  // as optimize --no-align
    if (run == 2) options.field.max_cluster_faces = 10;
    Pipeline pipeline(f->mesh, f->cage.layout, options);
    pipeline.compute_parameterization();
    const ParamMetrics m = pipeline.metrics();
    EXPECT_TRUE(std::isfinite(m.E));
    angle[run] = m.E_angle_deg;
    folds[run] = m.foldovers;
  }
  std::printf(
      "[stat] fertility: E° --no-align %.3f deg (%d fold-overs), aligned %.3f deg (%d), split "
      "clusters %.3f deg (%d)\n",
      angle[0], folds[0], angle[1], folds[1], angle[2], folds[2]);
  EXPECT_LT(angle[2], angle[0]);
}

}  // namespace
}  // namespace qs
