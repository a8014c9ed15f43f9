// Boundary "ears" (issue #4, inspired_mesh): a face whose two boundary edges both belong to one
// boundary-aligned arc, turning at a vertex that is not a node. Making every path vertex of the
// arc an iso-line vertex put all three corners of the ear on one line (parametric area exactly
// 0, E_confor ≈ 1e28). The ear's apex is left free instead; the traced arc cuts across the ear.
#include <gtest/gtest.h>

#include <cstdio>

#include "core/extract/metrics.h"
#include "core/field/curvature.h"
#include "core/import/quad_import.h"
#include "core/mesh/mesh_io.h"
#include "core/pipeline/pipeline.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

// Faces with two boundary edges whose shared vertex is not a node, both edges on one arc.
std::vector<int> ears_on_arcs(const TriMesh& mesh, const Layout& layout) {
  std::vector<int> node_at(mesh.n_vertices(), -1), arc_at(mesh.n_edges(), -1);
  for (const auto& n : layout.nodes) node_at[n.vertex] = n.id;
  for (size_t a = 0; a < layout.arcs.size(); ++a) {
    const auto& path = layout.arcs[a].path;
    for (size_t k = 0; k + 1 < path.size(); ++k) {
      const auto h =
          mesh.find_halfedge(mesh.vertex_handle(path[k]), mesh.vertex_handle(path[k + 1]));
      arc_at[mesh.edge_handle(h).idx()] = static_cast<int>(a);
    }
  }
  std::vector<int> ears;
  for (auto f : mesh.faces()) {
    for (auto h : mesh.fh_range(f)) {
      const auto n = mesh.next_halfedge_handle(h);
      const int e0 = mesh.edge_handle(h).idx(), e1 = mesh.edge_handle(n).idx();
      if (mesh.is_boundary(mesh.edge_handle(h)) && mesh.is_boundary(mesh.edge_handle(n)) &&
          arc_at[e0] >= 0 && arc_at[e0] == arc_at[e1] &&
          node_at[mesh.to_vertex_handle(h).idx()] < 0)
        ears.push_back(f.idx());
    }
  }
  return ears;
}

TEST(ParamEar, InspiredMeshEarsAreNotFlattened) {
  const std::string dir = test::shared_meshes_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/data/meshes is absent";
  const PolyMesh quads = load_poly_mesh(dir + "/inspired_mesh/inspired_mesh_quads_Conjugate.off");
  const TriMesh target = load_mesh(dir + "/inspired_mesh/inspired_mesh.obj");
  QuadImportOptions io;
  io.coarsen = 8;
  // The coarsened complex routed onto the target's own vertices and edges (transfer_complex,
  // no refinement), where its boundary arcs turn at ears.
  const QuadImportResult imported = import_quads(quads, &target, io);
  const Layout layout = transfer_complex(imported.quads, imported.complex, target, io);
  const std::vector<int> ears = ears_on_arcs(target, layout);
  ASSERT_FALSE(ears.empty()) << "the case must contain an ear on a boundary arc";
  Pipeline pipeline(target, layout);
  const Parameterization& param = pipeline.compute_parameterization();
  for (int f : ears) EXPECT_GT(param_signed_area2(param.corner_uv, f), 0.0) << "ear face " << f;
  const ParamMetrics m = pipeline.metrics();
  std::printf(
      "[stat] inspired_mesh --coarsen 8 (--no-node-opt): %zu ears, E_confor %g, %d "
      "degenerate, %d fold-overs\n",
      ears.size(), m.E_confor, m.degenerate, m.foldovers);
  EXPECT_EQ(m.degenerate, 0);
  EXPECT_LT(m.E_confor, 100.0);
}

}  // namespace
}  // namespace qs
