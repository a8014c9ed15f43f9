// Cluster rotations of the curvature constraints must keep the field consistent with the
// layout (issue #4, bunny cage layout, 162 clusters: too many for the relaxed warm start):
// rounded against the smoothest field pinned along an arc (ClusterWarmStart::LayoutField, the
// default's fallback), not against the field of the largest cluster.
#include <gtest/gtest.h>

#include <cstdio>

#include "core/field/cross_field.h"
#include "core/import/cage.h"
#include "core/layout/validate.h"
#include "core/mesh/geometry.h"
#include "core/mesh/mesh_io.h"
#include "core/param/parameterization.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

struct Outcome {
  int clusters = 0;
  int foldovers = 0;
  int negative_arcs = 0;  //!< arcs whose end node lies behind the start along the arc's label
};

Outcome solve(const TriMesh& mesh, const Layout& layout, ClusterWarmStart mode) {
  const GeometryCache g = build_geometry(mesh);
  const LayoutTopology topo = build_topology(mesh, layout);
  CrossFieldOptions fo;
  fo.warm_start = mode;
  fo.max_cluster_faces = 0;  // whole clusters (split clusters always start from the layout field)
  const CrossField field = compute_cross_field(mesh, g, layout, topo, fo);
  ParamSolver solver(mesh, g, layout, topo, field.period_jump, field.theta);
  const Parameterization& p = solver.result();
  Outcome out;
  out.clusters = field.clusters;
  out.foldovers = p.foldovers;
  // Signed arc lengths: start node carried along the strip into the end chart.
  const Labeling& L = solver.labeling();
  auto at = [&](int f, int v) { return p.corner_uv[3 * f + corner_of(g, f, v)]; };
  for (int a = 0; a < topo.num_arcs; ++a) {
    const ArcStrip& s = L.strips[a];
    int r = 0;
    std::array<double, 2> t{0, 0};
    for (const auto st : s.steps) {
      const int w = mesh.from_vertex_handle(st).idx(), z = mesh.to_vertex_handle(st).idx();
      const int fi = mesh.face_handle(st).idx();
      const int fj = mesh.face_handle(mesh.opposite_halfedge_handle(st)).idx();
      const int re = step_rotation(field.period_jump[mesh.edge_handle(st).idx()], w, z);
      const auto ri = rotate(re, at(fi, w)), uj = at(fj, w), rt = rotate(re, t);
      t = {rt[0] + uj[0] - ri[0], rt[1] + uj[1] - ri[1]};
      r = (r + re) % 4;
    }
    const int hs = s.reversed ? 2 * a + 1 : 2 * a;
    const auto start = rotate(r, at(L.chart_face[hs], s.walk.front()));
    const auto end = at(L.chart_face[hs ^ 1], s.walk.back());
    const auto dir = rotate(L.symbol[hs] + r, {1.0, 0.0});
    const double len = (end[0] - start[0] - t[0]) * dir[0] + (end[1] - start[1] - t[1]) * dir[1];
    out.negative_arcs += len < 0;
  }
  return out;
}

TEST(FieldWarmStart, BunnyCageLayoutDoesNotCollapse) {
  const std::string dir = test::shared_meshes_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/data/meshes is absent";
  const TriMesh mesh = load_mesh(dir + "/bunny.off");
  CageOptions co;
  co.resolution = 8;
  const CageResult cage = cage_layout(mesh, co);
  ASSERT_TRUE(validate_layout(mesh, cage.layout).valid());
  const Outcome largest = solve(mesh, cage.layout, ClusterWarmStart::LargestCluster);
  const Outcome layout = solve(mesh, cage.layout, ClusterWarmStart::LayoutField);
  // The default (Relaxed) cannot relax this many clusters and falls back to LayoutField.
  const Outcome fallback = solve(mesh, cage.layout, CrossFieldOptions{}.warm_start);
  std::printf(
      "[stat] bunny cage (%zu arcs, %d clusters): fold-overs %d (largest cluster) vs %d "
      "(layout field) of %zu faces; arcs running backwards %d vs %d\n",
      cage.layout.arcs.size(), layout.clusters, largest.foldovers, layout.foldovers, mesh.n_faces(),
      largest.negative_arcs, layout.negative_arcs);
  ASSERT_GT(layout.clusters, 64) << "the case must exceed the relaxed warm start's cluster limit";
  // Before: the clusters twisted the field by quarter turns against the arcs and the
  // parameterization collapsed (40% of the faces folded, arcs running backwards).
  EXPECT_EQ(layout.negative_arcs, 0);
  EXPECT_LT(layout.foldovers, static_cast<int>(mesh.n_faces()) / 10);
  EXPECT_LT(2 * layout.foldovers, largest.foldovers);
  EXPECT_EQ(fallback.foldovers, layout.foldovers);
  EXPECT_EQ(fallback.negative_arcs, layout.negative_arcs);
}

}  // namespace
}  // namespace qs
