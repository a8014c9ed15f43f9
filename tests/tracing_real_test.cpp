// Arc tracing on real inputs (issue #4): every arc that fails to trace does so at a defect of
// the parameterization (a folded face around its start or end node or along its trace, or a
// start or end node whose parametric cone angle is not valence·90°), never on a clean chart; a
// fold-free parameterization with correct cones is structurally equivalent.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/import/cage.h"
#include "core/import/quad_import.h"
#include "core/mesh/mesh_io.h"
#include "core/pipeline/pipeline.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

void check_failures_are_at_folds(const std::string& name, const TriMesh& mesh,
                                 const Layout& layout) {
  Pipeline pipeline(mesh, layout);
  const Parameterization& param = pipeline.compute_parameterization();
  const Extraction& ex = pipeline.extract();
  const GeometryCache& g = pipeline.geometry();
  const TriMesh& m = pipeline.mesh();
  std::vector<char> folded(g.n_faces, 0);
  int foldovers = 0;
  for (int f = 0; f < g.n_faces; ++f)
    foldovers += folded[f] = param_signed_area2(param.corner_uv, f) <= 0;
  auto fold_near = [&](int v) {
    for (auto f : m.vf_range(m.vertex_handle(v)))
      if (folded[f.idx()]) return true;
    return false;
  };
  // Parametric cone angle at each interior node vertex (corner angles in their own charts).
  std::vector<char> bad_cone(layout.nodes.size(), 0);
  int bad_cones = 0;
  for (size_t n = 0; n < layout.nodes.size(); ++n) {
    const int w = layout.nodes[n].vertex;
    if (g.vertex_on_boundary[w]) continue;
    double cone = 0;
    for (auto f : m.vf_range(m.vertex_handle(w))) {
      int k = 0;
      while (g.face_vertices[f.idx()][k] != w) ++k;
      const auto& c0 = param.corner_uv[3 * f.idx() + k];
      const auto& c1 = param.corner_uv[3 * f.idx() + (k + 1) % 3];
      const auto& c2 = param.corner_uv[3 * f.idx() + (k + 2) % 3];
      const double ax = c1[0] - c0[0], ay = c1[1] - c0[1], bx = c2[0] - c0[0], by = c2[1] - c0[1];
      cone += std::atan2(ax * by - ay * bx, ax * bx + ay * by);
    }
    bad_cones += bad_cone[n] =
        std::abs(cone - pipeline.topology().valence[n] * M_PI / 2) > M_PI / 4;
  }
  EXPECT_EQ(ex.bad_cones, bad_cones);
  int failed = 0;
  for (size_t a = 0; a < ex.arcs.size(); ++a) {
    const TracedArc& t = ex.arcs[a];
    if (t.ok) continue;
    ++failed;
    const int start = pipeline.topology().half_node[2 * a];
    const int end = pipeline.topology().half_node[2 * a + 1];
    bool at_fold = bad_cone[start] || fold_near(layout.nodes[start].vertex) ||
                   (end >= 0 && (bad_cone[end] || fold_near(layout.nodes[end].vertex)));
    for (const auto& s : t.samples)
      for (int v : g.face_vertices[s.face]) at_fold = at_fold || fold_near(v);
    EXPECT_TRUE(at_fold) << name << ": arc " << a << " failed on a fold-free chart: " << t.failure;
    if (!bad_cone[start] && t.samples.empty()) {  // failed at the start: names the fold
      EXPECT_NE(t.failure.find("folded"), std::string::npos) << t.failure;
    }
  }
  std::printf(
      "[stat] %s (--no-node-opt): %d fold-overs, %d nodes with a wrong cone angle, %d "
      "of %zu arcs not traced, %d crossings\n",
      name.c_str(), foldovers, bad_cones, failed, ex.arcs.size(), ex.crossings);
  EXPECT_EQ(param.foldovers, foldovers);
  if (foldovers == 0 && bad_cones == 0) {
    EXPECT_TRUE(ex.structurally_equivalent);
  }
  EXPECT_EQ(ex.structurally_equivalent, failed == 0 && ex.crossings == 0);
}

TEST(TracingReal, SpotFailuresAreAtFoldOvers) {
  const std::string dir = test::shared_meshes_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/data/meshes is absent";
  const PolyMesh quads = load_poly_mesh(dir + "/spot/spot_quadrangulated.obj");
  const QuadImportResult in = import_quads(quads, nullptr);
  check_failures_are_at_folds("spot", in.mesh, in.layout);
}

TEST(TracingReal, FandiskFailuresAreAtFoldOvers) {
  const std::string dir = test::shared_meshes_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/data/meshes is absent";
  const PolyMesh quads = load_poly_mesh(dir + "/fandisk/fandisk_quads.off");
  const TriMesh target = load_mesh(dir + "/fandisk/fandisk.off");
  const QuadImportResult in = import_quads(quads, &target);
  check_failures_are_at_folds("fandisk", in.mesh, in.layout);
}

TEST(TracingReal, ThreeHolesCageFailuresAreAtFoldsOrWrongCones) {
  // A fold-free failure: a valence-5 node whose faces are all positive but wind 90° instead of
  // 450° (every arc then leaves within one quarter; "no start sector" without any fold).
  const std::string dir = test::shared_meshes_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/data/meshes is absent";
  const TriMesh mesh = load_mesh(dir + "/3holes.off");
  CageOptions co;
  co.resolution = 10;
  const CageResult cage = cage_layout(mesh, co);
  check_failures_are_at_folds("3holes cage", mesh, cage.layout);
}

}  // namespace
}  // namespace qs
