// Tests of the base complex of quad meshes (core/import/base_complex.h) and its coarsening
// (core/import/coarsen.h).
#include "core/import/base_complex.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "core/base/errors.h"
#include "core/import/coarsen.h"
#include "core/mesh/mesh_io.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

using VH = OpenMesh::VertexHandle;
using test::notched_disk;
using test::quad_cube;
using test::quad_disk;
using test::quad_torus;

//! Checks the derived fields of a complex: valences, half-arc lists, arc ends.
void expect_consistent(const QuadComplex& qc, const std::string& what) {
  ASSERT_EQ(qc.valence.size(), qc.node_vertex.size()) << what;
  ASSERT_EQ(qc.node_half_arcs.size(), qc.node_vertex.size()) << what;
  std::vector<int> ends(qc.node_vertex.size(), 0);
  for (const auto& arc : qc.arcs) {
    ASSERT_GE(arc.path.size(), 2u) << what;
    EXPECT_EQ(arc.path.front(), qc.node_vertex[arc.from]) << what;
    EXPECT_EQ(arc.path.back(), qc.node_vertex[arc.to]) << what;
    ++ends[arc.from];
    ++ends[arc.to];
  }
  for (size_t n = 0; n < qc.node_vertex.size(); ++n) {
    EXPECT_EQ(qc.valence[n], ends[n]) << what << " node " << n;
    EXPECT_EQ(static_cast<int>(qc.node_half_arcs[n].size()), ends[n]) << what << " node " << n;
  }
}

TEST(BaseComplex, CubeHasEightCornersTwelveArcsSixPatches) {
  for (int k : {1, 2, 5}) {
    const PolyMesh cube = quad_cube(k);
    ASSERT_EQ(cube.n_faces(), static_cast<size_t>(6 * k * k));
    const QuadComplex qc = base_complex(cube);
    EXPECT_EQ(qc.irregular_vertices, 8);
    EXPECT_EQ(qc.node_vertex.size(), 8u) << "k = " << k;
    EXPECT_EQ(qc.arcs.size(), 12u);
    EXPECT_EQ(qc.num_patches, 6);
    for (int v : qc.valence) EXPECT_EQ(v, 3);
    for (const auto& arc : qc.arcs) {
      EXPECT_EQ(arc.path.size(), static_cast<size_t>(k + 1));
      EXPECT_EQ(arc.path.front(), qc.node_vertex[arc.from]);
      EXPECT_EQ(arc.path.back(), qc.node_vertex[arc.to]);
    }
  }
}

TEST(BaseComplex, DiskGridIsOnePatch) {
  // The corners (boundary valence 2) are the only irregular vertices; their separatrices run
  // along the boundary, so the complex is the boundary rectangle.
  const QuadComplex disk = base_complex(quad_disk(4, 3));
  EXPECT_EQ(disk.node_vertex.size(), 4u);  // the corners
  EXPECT_EQ(disk.arcs.size(), 4u);         // the four sides
  EXPECT_EQ(disk.num_patches, 1);
  for (int v : disk.valence) EXPECT_EQ(v, 2);
}

TEST(BaseComplex, NoIrregularVertexNeedsAllEdges) {
  const PolyMesh torus = quad_torus(6, 4);
  try {
    base_complex(torus);
    FAIL() << "expected InvalidInputError";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("--all-edges"), std::string::npos) << e.what();
  }
  BaseComplexOptions options;
  options.all_edges = true;
  const QuadComplex qc = base_complex(torus, options);
  EXPECT_EQ(qc.node_vertex.size(), 24u);
  EXPECT_EQ(qc.arcs.size(), 48u);
  EXPECT_EQ(qc.num_patches, 24);
  for (int v : qc.valence) EXPECT_EQ(v, 4);
}

TEST(BaseComplex, AllEdgesOnCube) {
  BaseComplexOptions options;
  options.all_edges = true;
  const PolyMesh cube = quad_cube(2);
  const QuadComplex qc = base_complex(cube, options);
  EXPECT_EQ(qc.node_vertex.size(), cube.n_vertices());
  EXPECT_EQ(qc.arcs.size(), cube.n_edges());
  EXPECT_EQ(qc.num_patches, static_cast<int>(cube.n_faces()));
}

TEST(BaseComplex, HalfArcOrderIsCounterClockwise) {
  // At the corner (0,0,0) of the cube the three arcs go to +x, +y, +z; seen from outside
  // (from (-1,-1,-1)) the counter-clockwise order is x, z, y.
  const PolyMesh cube = quad_cube(1);
  const QuadComplex qc = base_complex(cube);
  int origin = -1;
  for (size_t n = 0; n < qc.node_vertex.size(); ++n)
    if (cube.point(VH(qc.node_vertex[n])).sqrnorm() == 0) origin = static_cast<int>(n);
  ASSERT_GE(origin, 0);
  std::vector<int> axis_order;
  for (int h : qc.node_half_arcs[origin]) {
    const auto& arc = qc.arcs[h >> 1];
    const int far = (h & 1) ? arc.path[arc.path.size() - 2] : arc.path[1];
    const Vec3 d = cube.point(VH(far));
    axis_order.push_back(d[0] > 0 ? 0 : d[1] > 0 ? 1 : 2);
  }
  ASSERT_EQ(axis_order.size(), 3u);
  std::rotate(axis_order.begin(), std::find(axis_order.begin(), axis_order.end(), 0),
              axis_order.end());
  EXPECT_EQ(axis_order, (std::vector<int>{0, 2, 1}));
}

TEST(BaseComplex, SplitToQuadsKeepsOriginalVertices) {
  PolyMesh mesh;
  // A pyramid: square base and 4 triangles.
  std::vector<VH> v;
  for (const Vec3& p : {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)})
    v.push_back(mesh.add_vertex(p));
  v.push_back(mesh.add_vertex(Vec3(0.5, 0.5, 1)));
  mesh.add_face(std::vector<VH>{v[3], v[2], v[1], v[0]});
  for (int i = 0; i < 4; ++i) mesh.add_face(v[i], v[(i + 1) % 4], v[4]);
  EXPECT_FALSE(is_pure_quad(mesh));
  const PolyMesh quads = split_to_quads(mesh);
  EXPECT_TRUE(is_pure_quad(quads));
  EXPECT_EQ(quads.n_faces(), 4u + 4 * 3);
  EXPECT_EQ(quads.n_vertices(), mesh.n_vertices() + mesh.n_edges() + mesh.n_faces());
  for (const auto vh : mesh.vertices()) EXPECT_EQ(quads.point(vh), mesh.point(vh));
  // Corners of the pyramid: the apex (valence 4 before, still 4) is regular; the base corners
  // have valence 3: 4 irregular + 5 face centres (valence 4 for the square, 3 for triangles).
  const QuadComplex qc = base_complex(quads);
  EXPECT_EQ(qc.irregular_vertices, 8);
}

TEST(BaseComplex, RealQuadMeshes) {
  const std::string dir = test::shared_meshes_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/data/meshes not found; real quad meshes skipped";
  struct Case {
    std::string file;
    int irregular;
  };
  // Irregular-vertex counts from ../shared/data/SOURCES.md (boundary corners included).
  for (const Case& c :
       {Case{"spot/spot_quadrangulated.obj", 100}, Case{"fandisk/fandisk_quads.off", 30},
        Case{"quadwild_joint/joint_rem_p_quadrangulation.obj", 46},
        Case{"animals_basemesh/cat_cat.obj", 370}}) {
    const PolyMesh quads = load_poly_mesh(dir + "/" + c.file);
    const QuadComplex qc = base_complex(quads);
    EXPECT_EQ(qc.irregular_vertices, c.irregular) << c.file;
    // Closed surfaces: V - E + F of the complex equals that of the quad mesh.
    const int chi = static_cast<int>(quads.n_vertices()) - static_cast<int>(quads.n_edges()) +
                    static_cast<int>(quads.n_faces());
    EXPECT_EQ(
        static_cast<int>(qc.node_vertex.size()) - static_cast<int>(qc.arcs.size()) + qc.num_patches,
        chi)
        << c.file;
    int irregular_nodes = 0;
    for (int v : qc.valence) irregular_nodes += v != 4;
    EXPECT_EQ(irregular_nodes, c.irregular) << c.file;
  }
}

TEST(BaseComplexCoarsen, ThinBoundaryStripsCollapseToOnePatch) {
  const PolyMesh disk = notched_disk(8);
  const QuadComplex full = base_complex(disk);
  // Corners (0,0), (8,0), (0,8), (8,7), (7,8), the concave corner (7,7) and the two boundary
  // T-nodes (7,0), (0,7): three patches, two of them one cell wide.
  EXPECT_EQ(full.node_vertex.size(), 8u);
  EXPECT_EQ(full.num_patches, 3);
  CoarsenOptions options;
  options.max_width = 0.5;  // thinner than any strip: nothing changes
  CoarsenStats stats;
  const QuadComplex same = coarsen_complex(disk, full, options, &stats);
  EXPECT_EQ(stats.chords_collapsed, 0);
  EXPECT_EQ(same.node_vertex, full.node_vertex);
  EXPECT_TRUE(same.simple_paths);

  // The two one-cell strips (the second one is up to 2 edges wide after the first collapse
  // moved its corner), not the 7-cell ones.
  options.max_width = 2.5;
  const QuadComplex coarse = coarsen_complex(disk, full, options, &stats);
  EXPECT_TRUE(stats.skipped.empty()) << stats.skipped;
  EXPECT_EQ(stats.chords_collapsed, 2);
  EXPECT_EQ(stats.nodes_before, 8);
  EXPECT_EQ(stats.patches_before, 3);
  EXPECT_EQ(coarse.node_vertex.size(), 4u);
  EXPECT_EQ(coarse.arcs.size(), 4u);
  EXPECT_EQ(coarse.num_patches, 1);
  EXPECT_EQ(stats.nodes_after, 4);
  EXPECT_FALSE(coarse.simple_paths);
  expect_consistent(coarse, "notched disk");
  for (int v : coarse.valence) EXPECT_EQ(v, 2);
  // All nodes stay on the boundary, within one cell of a corner of the 8 x 8 square.
  for (int v : coarse.node_vertex) {
    EXPECT_TRUE(disk.is_boundary(VH(v)));
    const Vec3 p = disk.point(VH(v));
    const double dx = std::min(p[0], 8 - p[0]), dy = std::min(p[1], 8 - p[1]);
    EXPECT_LE(dx, 1.0);
    EXPECT_LE(dy, 1.0);
  }
}

TEST(BaseComplexCoarsen, ThinBoxKeepsItsCorners) {
  // A 6 x 6 x 1 box: the chord around the thin side is one cell wide, but collapsing it would
  // merge the valence-3 corners pairwise into valence-2 nodes (a degenerate pillow), so the
  // valence rule keeps the 8-corner layout.
  const PolyMesh box = test::quad_box({6, 6, 1});
  const QuadComplex full = base_complex(box);
  ASSERT_EQ(full.node_vertex.size(), 8u);
  CoarsenOptions options;
  options.max_width = 1.5;
  CoarsenStats stats;
  const QuadComplex coarse = coarsen_complex(box, full, options, &stats);
  EXPECT_EQ(stats.chords_collapsed, 0);
  EXPECT_EQ(coarse.node_vertex.size(), 8u);
  EXPECT_EQ(coarse.num_patches, 6);
}

TEST(BaseComplexCoarsen, RealDenseComplexesGetSmallerAndKeepTopology) {
  const std::string dir = test::shared_meshes_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/data/meshes not found; real quad meshes skipped";
  struct Case {
    std::string quads, target;
    int euler;  // V - E + F of the surface
  };
  for (const Case& c : {Case{"quadwild_joint/joint_rem_p_quadrangulation.obj",
                             "quadwild_joint/joint_rem_p.obj", -2},
                        Case{"inspired_mesh/inspired_mesh_quads_Conjugate.off",
                             "inspired_mesh/inspired_mesh.obj", 1}}) {
    const PolyMesh quads = load_poly_mesh(dir + "/" + c.quads);
    const TriMesh target = load_mesh(dir + "/" + c.target);
    double sum = 0;
    for (const auto e : target.edges()) sum += target.calc_edge_length(e);
    const QuadComplex full = base_complex(quads);
    CoarsenOptions options;
    options.max_width = 4.0 * sum / target.n_edges();
    CoarsenStats stats;
    const QuadComplex coarse = coarsen_complex(quads, full, options, &stats);
    EXPECT_TRUE(stats.skipped.empty()) << c.quads << ": " << stats.skipped;
    EXPECT_GT(stats.chords_collapsed, 0) << c.quads;
    EXPECT_LT(coarse.node_vertex.size(), full.node_vertex.size()) << c.quads;
    EXPECT_LT(coarse.num_patches, full.num_patches) << c.quads;
    EXPECT_EQ(static_cast<int>(full.node_vertex.size() - full.arcs.size()) + full.num_patches,
              c.euler)
        << c.quads;
    EXPECT_EQ(static_cast<int>(coarse.node_vertex.size() - coarse.arcs.size()) + coarse.num_patches,
              c.euler)
        << c.quads;
    expect_consistent(coarse, c.quads);
    // Merged nodes keep valences in the allowed ranges.
    for (size_t n = 0; n < coarse.node_vertex.size(); ++n) {
      const bool boundary = quads.is_boundary(VH(coarse.node_vertex[n]));
      EXPECT_GE(coarse.valence[n], boundary ? 2 : 3) << c.quads << " node " << n;
    }
  }
}

}  // namespace
}  // namespace qs
