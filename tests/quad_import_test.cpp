// Tests of importing quad-mesh layouts (core/layout/quad_import.h) and of
// `quadsketch-cli import-quads`.
#include "core/layout/quad_import.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/base/errors.h"
#include "core/layout/validate.h"
#include "core/mesh/closest_point.h"
#include "core/mesh/mesh_io.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

using VH = OpenMesh::VertexHandle;
using test::notched_disk;
using test::quad_cube;
using test::quad_torus;

//! Checks that an import validates and has the complex's patch count and node valences.
void expect_matches_complex(const QuadImportResult& r, const std::string& what) {
  const ValidationResult vr = validate_layout(r.mesh, r.layout);
  ASSERT_TRUE(vr.valid()) << what << ": " << (vr.issues.empty() ? "" : format_issue(vr.issues[0]));
  const LayoutTopology topo = build_topology(r.mesh, r.layout);
  EXPECT_EQ(static_cast<int>(topo.patches.size()), r.complex.num_patches) << what;
  ASSERT_EQ(topo.valence.size(), r.complex.valence.size()) << what;
  EXPECT_EQ(topo.valence, r.complex.valence) << what;
}

TEST(Triangulate, RefineSharesEdgePointsAndKeepsQuadVerticesFirst) {
  const PolyMesh cube = quad_cube(2);
  for (int k : {1, 2, 3}) {
    const TriMesh mesh = triangulate_quads(cube, k);
    EXPECT_EQ(mesh.n_vertices(),
              cube.n_vertices() + cube.n_edges() * (k - 1) + cube.n_faces() * (k - 1) * (k - 1));
    EXPECT_EQ(mesh.n_faces(), 2 * k * k * cube.n_faces());
    for (const auto v : cube.vertices()) EXPECT_EQ(mesh.point(VH(v.idx())), cube.point(v));
    // Closed and manifold: no boundary edge, Euler characteristic of a sphere.
    for (const auto e : mesh.edges()) ASSERT_FALSE(mesh.is_boundary(e));
    EXPECT_EQ(static_cast<int>(mesh.n_vertices() - mesh.n_edges() + mesh.n_faces()), 2);
  }
  EXPECT_THROW(triangulate_quads(cube, 0), InvalidInputError);
}

TEST(QuadImport, CubeAllEdgesRefined) {
  QuadImportOptions options;
  options.all_edges = true;
  for (int k : {1, 3}) {
    options.refine = k;
    const PolyMesh cube = quad_cube(2);
    const QuadImportResult r = import_quads(cube, nullptr, options);
    EXPECT_EQ(r.layout.nodes.size(), cube.n_vertices());  // 26
    EXPECT_EQ(r.layout.arcs.size(), cube.n_edges());      // 48
    for (const auto& arc : r.layout.arcs) EXPECT_EQ(arc.path.size(), static_cast<size_t>(k + 1));
    expect_matches_complex(r, "cube k=" + std::to_string(k));
    EXPECT_EQ(r.complex.num_patches, 24);
  }
}

TEST(QuadImport, TorusGridAllEdgesRefined) {
  QuadImportOptions options;
  options.all_edges = true;
  options.refine = 2;
  const QuadImportResult r = import_quads(quad_torus(8, 5), nullptr, options);
  EXPECT_EQ(r.layout.nodes.size(), 40u);
  EXPECT_EQ(r.layout.arcs.size(), 80u);
  expect_matches_complex(r, "torus");
  EXPECT_EQ(r.complex.num_patches, 40);
  // Without --all-edges a torus grid has no base complex.
  EXPECT_THROW(import_quads(quad_torus(8, 5), nullptr, {}), InvalidInputError);
}

TEST(QuadImport, CubeBaseComplexOntoSphereLikeMesh) {
  // The quad cube transferred onto a finer triangulation of the same cube.
  const PolyMesh coarse = quad_cube(4);
  const TriMesh target = triangulate_quads(quad_cube(12, Vec3(0, 0, 0)), 1);
  // Scale: quad_cube(12) spans [0,12]; the coarse one [0,4]: rescale the coarse one.
  PolyMesh scaled = coarse;
  for (const auto v : scaled.vertices()) scaled.point(v) *= 3.0;
  const QuadImportResult r = import_quads(scaled, &target, {});
  expect_matches_complex(r, "cube onto cube");
  EXPECT_EQ(r.layout.nodes.size(), 8u);
  EXPECT_EQ(r.layout.arcs.size(), 12u);
  // Corners land exactly on the target's corners.
  for (size_t n = 0; n < 8; ++n) {
    EXPECT_NEAR(
        (target.point(VH(r.layout.nodes[n].vertex)) - scaled.point(VH(r.complex.node_vertex[n])))
            .norm(),
        0.0, 1e-12);
  }
}

TEST(QuadImport, CoarsenedNotchedDiskIsOnePatch) {
  QuadImportOptions options;
  options.coarsen = 2.5;  // quad-mesh edge lengths (1 here)
  options.refine = 3;
  const QuadImportResult r = import_quads(notched_disk(8), nullptr, options);
  EXPECT_EQ(r.coarsen.nodes_before, 8);
  EXPECT_EQ(r.coarsen.patches_before, 3);
  EXPECT_EQ(r.coarsen.chords_collapsed, 2);
  expect_matches_complex(r, "notched disk");
  EXPECT_EQ(r.layout.nodes.size(), 4u);
  EXPECT_EQ(r.layout.arcs.size(), 4u);
  EXPECT_EQ(r.complex.num_patches, 1);
  // Without coarsening the exact base complex (3 patches) is kept.
  options.coarsen = 0;
  const QuadImportResult exact = import_quads(notched_disk(8), nullptr, options);
  expect_matches_complex(exact, "notched disk, exact");
  EXPECT_EQ(exact.complex.num_patches, 3);
}

TEST(QuadImport, FarFromTargetIsAnError) {
  const PolyMesh quads = quad_cube(2, Vec3(50, 0, 0));
  const TriMesh target = triangulate_quads(quad_cube(6), 1);
  try {
    import_quads(quads, &target, {});
    FAIL() << "expected InvalidInputError";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("does not lie on the target mesh"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("node 0"), std::string::npos) << e.what();
  }
}

TEST(QuadImportCli, WritesMeshAndLayoutAndRejectsBadInput) {
  const std::string dir = test::temp_dir("import_quads_cli");
  test::write_obj(quad_cube(2), dir + "/cube.obj");
  std::string output;
  const std::string out = dir + "/out";
  ASSERT_EQ(test::run_command(test::cli_path() + " import-quads --quads " + dir +
                                  "/cube.obj --all-edges --refine 2 --out " + out,
                              &output),
            0)
      << output;
  EXPECT_TRUE(std::filesystem::exists(out + "/mesh.obj"));
  EXPECT_TRUE(std::filesystem::exists(out + "/report.json"));
  ASSERT_EQ(test::run_command(test::cli_path() + " validate --mesh " + out + "/mesh.obj --layout " +
                                  out + "/layout.json",
                              &output),
            0)
      << output;
  EXPECT_NE(output.find("26 nodes"), std::string::npos) << output;
  EXPECT_NE(output.find("24 patches"), std::string::npos) << output;

  // Non-manifold quad mesh: three quads on one edge.
  {
    std::ofstream bad(dir + "/nonmanifold.obj");
    bad << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 1 -1 0\nv 0 -1 0\nv 1 0 1\nv 0 0 1\n"
           "f 1 2 3 4\nf 2 1 6 5\nf 1 2 7 8\n";
  }
  EXPECT_EQ(test::run_command(test::cli_path() + " import-quads --quads " + dir +
                                  "/nonmanifold.obj --out " + dir + "/bad1",
                              &output),
            2)
      << output;
  EXPECT_NE(output.find("nonmanifold.obj"), std::string::npos) << output;

  // A quad mesh far from the --onto surface.
  test::write_obj(quad_cube(2, Vec3(100, 0, 0)), dir + "/far.obj");
  test::write_obj(triangulate_quads(quad_cube(2), 2), dir + "/target.obj");
  EXPECT_EQ(test::run_command(test::cli_path() + " import-quads --quads " + dir +
                                  "/far.obj --onto " + dir + "/target.obj --out " + dir + "/bad2",
                              &output),
            2)
      << output;
  EXPECT_NE(output.find("does not lie on the target mesh"), std::string::npos) << output;
}

// ---- real inputs (../shared) ----

class RealQuads : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::shared_meshes_dir();
    if (dir_.empty()) GTEST_SKIP() << "../shared/data/meshes not found; real quad meshes skipped";
  }
  std::string dir_;
};

TEST_F(RealQuads, SpotOntoItself) {
  const QuadImportResult r =
      import_quads(load_poly_mesh(dir_ + "/spot/spot_quadrangulated.obj"), nullptr, {});
  expect_matches_complex(r, "spot");
  EXPECT_EQ(r.layout.nodes.size(), 370u);
  EXPECT_EQ(r.complex.num_patches, 368);
}

TEST_F(RealQuads, SpotControlMeshIsSplitWithAWarning) {
  const QuadImportResult r =
      import_quads(load_poly_mesh(dir_ + "/spot/spot_control_mesh.obj"), nullptr, {});
  EXPECT_TRUE(r.split);
  ASSERT_FALSE(r.warnings.empty());
  expect_matches_complex(r, "spot control mesh");
}

TEST_F(RealQuads, FandiskOntoFandisk) {
  const PolyMesh quads = load_poly_mesh(dir_ + "/fandisk/fandisk_quads.off");
  const TriMesh target = load_mesh(dir_ + "/fandisk/fandisk.off");
  const QuadImportResult r = import_quads(quads, &target, {});
  expect_matches_complex(r, "fandisk");
  EXPECT_EQ(r.layout.nodes.size(), 410u);
  double sum = 0;
  for (const auto e : target.edges()) sum += target.calc_edge_length(e);
  const double mean_edge = sum / target.n_edges();
  for (size_t n = 0; n < r.layout.nodes.size(); ++n) {
    const double d =
        (target.point(VH(r.layout.nodes[n].vertex)) - quads.point(VH(r.complex.node_vertex[n])))
            .norm();
    EXPECT_LE(d, mean_edge) << "node " << n;
  }
}

TEST_F(RealQuads, AnimalsRefined) {
  QuadImportOptions options;
  options.refine = 3;
  for (const char* name : {"cat_cat.obj", "cow_cow.obj", "pig_pig.obj"}) {
    const QuadImportResult r = import_quads(
        load_poly_mesh(dir_ + "/animals_basemesh/" + std::string(name)), nullptr, options);
    expect_matches_complex(r, name);
  }
}

TEST_F(RealQuads, JointAndInspiredOnTheirOwnQuads) {
  // Their base complexes are dense (the joint's separatrices spiral: 3751 nodes; the
  // inspired mesh's staircase boundary makes every vertex a node), so they validate on the
  // triangulated quad mesh ...
  for (const char* file : {"quadwild_joint/joint_rem_p_quadrangulation.obj",
                           "inspired_mesh/inspired_mesh_quads_Conjugate.off"}) {
    const QuadImportResult r = import_quads(load_poly_mesh(dir_ + "/" + file), nullptr, {});
    expect_matches_complex(r, file);
  }
}

TEST_F(RealQuads, DenseComplexOntoCoarseTargetFailsClearly) {
  // ... but not onto their coarser triangle meshes (known limitation, see the import report):
  // the error names the nodes and says why.
  const PolyMesh quads = load_poly_mesh(dir_ + "/quadwild_joint/joint_rem_p_quadrangulation.obj");
  const TriMesh target = load_mesh(dir_ + "/quadwild_joint/joint_rem_p.obj");
  try {
    import_quads(quads, &target, {});
    FAIL() << "expected InvalidInputError";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("too coarse"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--coarsen"), std::string::npos) << e.what();
  }
}

TEST_F(RealQuads, InspiredCoarsenedOntoItsTriangleMesh) {
  // The staircase boundary makes almost every vertex a node of the base complex; collapsing its
  // thin chords makes the transfer onto the (boundary) triangle mesh possible.
  const PolyMesh quads = load_poly_mesh(dir_ + "/inspired_mesh/inspired_mesh_quads_Conjugate.off");
  const TriMesh target = load_mesh(dir_ + "/inspired_mesh/inspired_mesh.obj");
  QuadImportOptions options;
  options.coarsen = 6;
  const QuadImportResult r = import_quads(quads, &target, options);
  expect_matches_complex(r, "inspired coarsened");
  EXPECT_EQ(r.coarsen.nodes_before, 1749);
  EXPECT_LT(r.coarsen.nodes_after, 200);
  EXPECT_EQ(static_cast<int>(r.layout.nodes.size()), r.coarsen.nodes_after);
  // A disk: one boundary loop, V - E + F = 1, covered by boundary arcs (no trimmed patch).
  const LayoutTopology topo = build_topology(r.mesh, r.layout);
  EXPECT_EQ(topo.num_nodes - topo.num_arcs + static_cast<int>(topo.patches.size()), 1);
  for (const auto& patch : topo.patches) EXPECT_FALSE(patch.trimmed);
  // Without coarsening the same transfer fails with a hint.
  try {
    import_quads(quads, &target, {});
    FAIL() << "expected InvalidInputError";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("--coarsen"), std::string::npos) << e.what();
  }
}

TEST_F(RealQuads, JointCoarsenedOnItsOwnQuads) {
  // The spiralling base complex of the QuadWild joint, coarsened by chord collapse, routed onto
  // the quad mesh refined 3 x 3: a valid genus-2 layout with fewer patches.
  QuadImportOptions options;
  options.coarsen = 4;
  options.refine = 3;
  const QuadImportResult r = import_quads(
      load_poly_mesh(dir_ + "/quadwild_joint/joint_rem_p_quadrangulation.obj"), nullptr, options);
  expect_matches_complex(r, "joint coarsened");
  EXPECT_GT(r.coarsen.chords_collapsed, 0);
  EXPECT_LT(r.coarsen.nodes_after, r.coarsen.nodes_before);
  EXPECT_EQ(static_cast<int>(r.layout.nodes.size()), r.coarsen.nodes_after);
  const LayoutTopology topo = build_topology(r.mesh, r.layout);
  EXPECT_EQ(topo.num_nodes - topo.num_arcs + static_cast<int>(topo.patches.size()), -2);
}

}  // namespace
}  // namespace qs
