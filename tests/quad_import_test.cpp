// Tests of importing quad-mesh layouts (core/import/quad_import.h) and of
// `quadsketch-cli import-quads`.
#include "core/import/quad_import.h"

#include <gtest/gtest.h>

#include <OpenMesh/Tools/Subdivider/Uniform/CatmullClarkT.hh>
#include <OpenMesh/Tools/Subdivider/Uniform/LoopT.hh>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>

#include "core/base/errors.h"
#include "core/import/patch_import.h"
#include "core/layout/validate.h"
#include "core/mesh/closest_point.h"
#include "core/mesh/mesh_checks.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/weld.h"
#include "core/mesh/write_checks.h"
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
  // Corners land exactly on the target's corners (its vertices, which the working mesh keeps).
  for (size_t n = 0; n < 8; ++n) {
    EXPECT_NEAR(
        (r.mesh.point(VH(r.layout.nodes[n].vertex)) - scaled.point(VH(r.complex.node_vertex[n])))
            .norm(),
        0.0, 1e-12);
    EXPECT_LT(r.layout.nodes[n].vertex, static_cast<int>(target.n_vertices()));
  }
  // The arcs keep to the cube's edges: every vertex of every arc has two coordinates at 0 or 12.
  for (const auto& arc : r.layout.arcs) {
    for (const int v : arc.path) {
      const Vec3 p = r.mesh.point(VH(v));
      int on_faces = 0;
      for (int k = 0; k < 3; ++k) on_faces += std::abs(p[k]) < 1e-9 || std::abs(p[k] - 12) < 1e-9;
      EXPECT_GE(on_faces, 2) << "arc " << arc.id << " vertex " << v << " at " << p;
    }
  }
}

//! A pentagonal prism (2 pentagons, 5 quads), outward oriented: a subdivision cage with n-gons.
PolyMesh pentagonal_prism() {
  PolyMesh m;
  std::vector<OpenMesh::VertexHandle> v;
  for (int ring = 0; ring < 2; ++ring)
    for (int i = 0; i < 5; ++i) {
      const double a = 2 * M_PI * i / 5;
      v.push_back(m.add_vertex(Vec3(2 * std::cos(a), 2 * std::sin(a), 3.0 * ring)));
    }
  m.add_face(std::vector<OpenMesh::VertexHandle>{v[4], v[3], v[2], v[1], v[0]});
  m.add_face(std::vector<OpenMesh::VertexHandle>{v[5], v[6], v[7], v[8], v[9]});
  for (int i = 0; i < 5; ++i) {
    const int j = (i + 1) % 5;
    m.add_face(std::vector<OpenMesh::VertexHandle>{v[i], v[j], v[5 + j], v[5 + i]});
  }
  return m;
}

//! The triangulated surface of \p levels Catmull-Clark steps of \p cage (n-gons as n-gons).
TriMesh subdivision_surface(const PolyMesh& cage, int levels) {
  PolyMesh fine = cage;
  OpenMesh::Subdivider::Uniform::CatmullClarkT<PolyMesh> subdivider;
  subdivider.attach(fine);
  subdivider(levels);
  subdivider.detach();
  return triangulate_quads(fine, 1);
}

TEST(QuadImport, CageWithNgonsOntoItsSubdivisionSurface) {
  // The cage lies off its subdivision surface (its corners up to a fifth of the diagonal away);
  // its base complex and all its edges transfer, the n-gons split into quads.
  const PolyMesh cage = pentagonal_prism();
  const TriMesh target = subdivision_surface(cage, 3);
  const QuadImportResult r = import_quads(cage, &target, {});
  EXPECT_TRUE(r.split);
  expect_matches_complex(r, "prism base complex");
  ASSERT_TRUE(r.working);
  EXPECT_LE(r.working->max_origin_error(), 1e-12);
  for (const auto v : target.vertices()) ASSERT_EQ(r.mesh.point(v), target.point(v));
  QuadImportOptions all;
  all.all_edges = true;
  const QuadImportResult e = import_quads(cage, &target, all);
  expect_matches_complex(e, "prism all edges");
  EXPECT_EQ(e.complex.num_patches, 5 * 4 + 2 * 5);
}

TEST(QuadImport, CoarsenedNotchedDiskIsOnePatch) {
  // The coarsened complex is transferred onto a working mesh of the triangulated quad mesh,
  // which needs no refinement up front (--refine 1).
  QuadImportOptions options;
  options.coarsen = 2.5;  // quad-mesh edge lengths (1 here)
  const QuadImportResult r = import_quads(notched_disk(8), nullptr, options);
  EXPECT_EQ(r.coarsen.nodes_before, 8);
  EXPECT_EQ(r.coarsen.patches_before, 3);
  EXPECT_EQ(r.coarsen.chords_collapsed, 2);
  expect_matches_complex(r, "notched disk");
  EXPECT_EQ(r.layout.nodes.size(), 4u);
  EXPECT_EQ(r.layout.arcs.size(), 4u);
  EXPECT_EQ(r.complex.num_patches, 1);
  ASSERT_TRUE(r.working);
  EXPECT_EQ(r.transfer.input_faces, 2 * static_cast<int>(r.quads.n_faces()));
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
    // The target's resolution is never the problem (the working mesh refines).
    EXPECT_EQ(std::string(e.what()).find("coarse"), std::string::npos) << e.what();
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

// ---- the importer's checks of its input and output (issue #44) ----

// quad_cube(4) with the grid lines x = 1 and y = 1 moved to 2 − w: on the sides z = 0 and z = 4
// the two thin strips cross in a w × w quad, of area 2.25e-12 for w = 1.5e-6: above the
// readers' zero-area bound (1e-14 × diagonal² = 4.8e-13), but its triangles at refine 3
// (area / 18) are below it.
PolyMesh thin_cross_cube() {
  PolyMesh quads = quad_cube(4);
  const double w = 1.5e-6;
  for (const auto v : quads.vertices()) {
    Vec3 p = quads.point(v);
    for (int axis : {0, 1})
      if (p[axis] == 1) p[axis] = 2 - w;
    quads.set_point(v, p);
  }
  return quads;
}

// Writes \p mesh as OBJ split into groups of \p group_size consecutive faces ("g part<i>"),
// each group with its own copies of its vertices, as Blender exports a mesh split by face
// groups. \p shift moves the copies of every second group (to test the weld tolerance).
void write_split_obj(const PolyMesh& mesh, int group_size, const std::string& path,
                     double shift = 0) {
  std::ofstream out(path);
  out.precision(17);
  int base = 1;
  const int faces = static_cast<int>(mesh.n_faces());
  for (int group = 0; group * group_size < faces; ++group) {
    out << "g part" << group << "\n";
    std::map<int, int> local;
    std::string lines;
    for (int f = group * group_size; f < std::min(faces, (group + 1) * group_size); ++f) {
      lines += "f";
      for (const auto v : mesh.fv_range(mesh.face_handle(f))) {
        if (!local.count(v.idx())) {
          local.emplace(v.idx(), base + static_cast<int>(local.size()));
          const Vec3 p = mesh.point(v) + Vec3(group % 2 ? shift : 0, 0, 0);
          out << "v " << p[0] << " " << p[1] << " " << p[2] << "\n";
        }
        lines += " " + std::to_string(local.at(v.idx()));
      }
      lines += "\n";
    }
    out << lines;
    base += static_cast<int>(local.size());
  }
}

TEST(QuadImport, TriangulationTheReadersRejectIsAnError) {
  const PolyMesh quads = thin_cross_cube();
  std::vector<int> tiny;  // the two w × w quads
  for (const auto f : quads.faces()) {
    std::vector<Vec3> c;
    for (const auto v : quads.fv_range(f)) c.push_back(quads.point(v));
    if ((c[2] - c[0]).norm() < 1e-5) tiny.push_back(f.idx());  // diagonal w·√2
  }
  ASSERT_EQ(tiny.size(), 2u);
  QuadImportOptions options;
  options.all_edges = true;
  options.refine = 3;
  try {
    import_quads(quads, nullptr, options);
    FAIL() << "a triangulation with zero-area triangles was accepted";
  } catch (const InvalidInputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("would be rejected when read back"), std::string::npos) << what;
    EXPECT_NE(what.find("36 degenerate faces"), std::string::npos) << what;  // 2 × 2 · 3²
    EXPECT_NE(what.find("the degenerate triangles lie in quads " + std::to_string(tiny[0]) + ", " +
                        std::to_string(tiny[1]) + ":"),
              std::string::npos)
        << what;
  }
  options.refine = 1;
  const QuadImportResult r = import_quads(quads, nullptr, options);
  EXPECT_TRUE(check_as_read(r.mesh).ok());
  expect_matches_complex(r, "thin cross, refine 1");
}

TEST(QuadImportCli, NeverWritesAMeshTheReadersReject) {
  const std::string dir = test::temp_dir("import_quads_cli_thin");
  test::write_obj(thin_cross_cube(), dir + "/thin.obj");
  std::string output;
  const std::string import =
      test::cli_path() + " import-quads --quads " + dir + "/thin.obj --all-edges --out ";
  EXPECT_EQ(test::run_command(import + dir + "/r3 --refine 3", &output), 2) << output;
  EXPECT_NE(output.find("would be rejected when read back"), std::string::npos) << output;
  EXPECT_NE(output.find("the degenerate triangles lie in quads"), std::string::npos) << output;
  EXPECT_FALSE(std::filesystem::exists(dir + "/r3/mesh.obj"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/r3/layout.json"));
  // At refine 1 the triangles are large enough, and the mesh written validates.
  ASSERT_EQ(test::run_command(import + dir + "/r1", &output), 0) << output;
  EXPECT_EQ(test::run_command(test::cli_path() + " validate --mesh " + dir + "/r1/mesh.obj" +
                                  " --layout " + dir + "/r1/layout.json",
                              &output),
            0)
      << output;
}

// A cube exported per side (6 parts, each with its own 9 vertices) is one surface again after
// welding: 54 − 26 = 28 vertices go. Copies apart by more than the tolerance stay apart.
TEST(QuadImport, WeldingJoinsAQuadMeshExportedPerPatch) {
  const std::string dir = test::temp_dir("quad_import_weld");
  const PolyMesh cube = quad_cube(2);
  write_split_obj(cube, 4, dir + "/split.obj");
  const WeldedPolyMesh loaded = load_poly_mesh_welded(dir + "/split.obj");
  EXPECT_EQ(loaded.welded, 28);
  EXPECT_EQ(loaded.parts_before, 6);
  EXPECT_EQ(loaded.mesh.n_vertices(), 26u);
  EXPECT_EQ(loaded.report.components, 1);
  ASSERT_EQ(loaded.mesh.n_faces(), cube.n_faces());
  const auto corners = [](const PolyMesh& mesh, int f) {
    std::vector<Vec3> points;
    for (const auto v : mesh.fv_range(mesh.face_handle(f))) points.push_back(mesh.point(v));
    return points;
  };
  for (int f = 0; f < static_cast<int>(cube.n_faces()); ++f)  // same corners, same order
    EXPECT_EQ(corners(cube, f), corners(loaded.mesh, f)) << "face " << f;
  // Within the tolerance (1e-9 × diagonal 6.9): welded; beyond it: 6 parts remain.
  write_split_obj(cube, 4, dir + "/near.obj", 1e-12);
  EXPECT_EQ(load_poly_mesh_welded(dir + "/near.obj").welded, 28);
  write_split_obj(cube, 4, dir + "/apart.obj", 1e-6);
  try {
    load_poly_mesh_welded(dir + "/apart.obj");
    FAIL() << "parts 1e-6 apart were welded";
  } catch (const InvalidInputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("connected components (expected 1)"), std::string::npos) << what;
  }
}

// When the welded mesh is still rejected, the error says that the parts touch at coincident
// vertices: two cubes sharing one corner become one part with a non-manifold vertex.
TEST(QuadImport, WeldingThatIsNotEnoughSaysWhereThePartsTouch) {
  const std::string dir = test::temp_dir("quad_import_weld_corner");
  PolyMesh two = quad_cube(1);
  const PolyMesh other = quad_cube(1, Vec3(1, 1, 1));
  std::vector<OpenMesh::VertexHandle> map;
  for (const auto v : other.vertices()) map.push_back(two.add_vertex(other.point(v)));
  for (const auto f : other.faces()) {
    std::vector<OpenMesh::VertexHandle> face;
    for (const auto v : other.fv_range(f)) face.push_back(map[v.idx()]);
    two.add_face(face);
  }
  test::write_obj(two, dir + "/corner.obj");
  try {
    load_poly_mesh_welded(dir + "/corner.obj");
    FAIL() << "two cubes sharing a corner were accepted";
  } catch (const InvalidInputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("after welding 1 coincident vertices, at which the file's 2 separate "
                        "parts touch"),
              std::string::npos)
        << what;
    EXPECT_NE(what.find("non-manifold vert"), std::string::npos) << what;
  }
}

TEST(QuadImportCli, WeldsAQuadMeshExportedPerPatch) {
  const std::string dir = test::temp_dir("import_quads_cli_weld");
  write_split_obj(quad_cube(2), 4, dir + "/split.obj");
  std::string output;
  ASSERT_EQ(test::run_command(test::cli_path() + " import-quads --quads " + dir +
                                  "/split.obj --all-edges --out " + dir + "/out",
                              &output),
            0)
      << output;
  EXPECT_NE(output.find("note: " + dir + "/split.obj: welded 28 coincident vertices"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("joining 6 separate parts"), std::string::npos) << output;
  EXPECT_EQ(test::run_command(test::cli_path() + " validate --mesh " + dir + "/out/mesh.obj" +
                                  " --layout " + dir + "/out/layout.json",
                              &output),
            0)
      << output;
  EXPECT_NE(output.find("26 nodes"), std::string::npos) << output;
  EXPECT_NE(output.find("24 patches"), std::string::npos) << output;
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
        (r.mesh.point(VH(r.layout.nodes[n].vertex)) - quads.point(VH(r.complex.node_vertex[n])))
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

TEST_F(RealQuads, DenseComplexOntoCoarserTargetTransfers) {
  // ... and onto their coarser triangle meshes too: the joint's base complex (3751 nodes, its
  // separatrices spiral) onto joint_rem_p.obj (4387 vertices), on a working mesh of it.
  const PolyMesh quads = load_poly_mesh(dir_ + "/quadwild_joint/joint_rem_p_quadrangulation.obj");
  const TriMesh target = load_mesh(dir_ + "/quadwild_joint/joint_rem_p.obj");
  const QuadImportResult r = import_quads(quads, &target, {});
  expect_matches_complex(r, "joint onto joint_rem_p");
  ASSERT_TRUE(r.working);
  EXPECT_EQ(r.transfer.input_vertices, static_cast<int>(target.n_vertices()));
  EXPECT_EQ(r.transfer.working_faces, static_cast<int>(r.mesh.n_faces()));
  EXPECT_LE(r.working->max_origin_error(), 1e-12);
  // The target's vertices come first, unmoved.
  for (const auto v : target.vertices()) ASSERT_EQ(r.mesh.point(v), target.point(v));
}

TEST_F(RealQuads, SpotCageOntoItsTriangleMesh) {
  // The control cage (quads, triangles and pentagons, off the surface) onto the triangulated
  // subdivision surface: its split into quads has the base complex of spot_quadrangulated.obj.
  const PolyMesh cage = load_poly_mesh(dir_ + "/spot/spot_control_mesh.obj");
  const TriMesh target = load_mesh(dir_ + "/spot/spot_triangulated.obj");
  const QuadImportResult r = import_quads(cage, &target, {});
  EXPECT_TRUE(r.split);
  expect_matches_complex(r, "spot cage onto spot_triangulated");
  EXPECT_EQ(r.layout.nodes.size(), 370u);
  EXPECT_EQ(r.complex.num_patches, 368);
  ASSERT_TRUE(r.working);
  EXPECT_LE(r.working->max_origin_error(), 1e-12);
  for (const auto v : target.vertices()) ASSERT_EQ(r.mesh.point(v), target.point(v));
  // All its edges transfer as well (one patch per quad of the split).
  QuadImportOptions all;
  all.all_edges = true;
  const QuadImportResult e = import_quads(cage, &target, all);
  expect_matches_complex(e, "spot cage, all edges");
  EXPECT_EQ(e.complex.num_patches, static_cast<int>(e.quads.n_faces()));
}

//! \p quads triangulated, 2 Loop subdivision steps, then 3 steps of Laplacian smoothing (each
//! vertex halfway to the mean of its neighbours): a smooth surface near \p quads whose vertices
//! are not those of \p quads.
TriMesh loop_smoothed(const PolyMesh& quads) {
  TriMesh mesh = triangulate_quads(quads, 1);
  OpenMesh::Subdivider::Uniform::LoopT<TriMesh> loop;
  loop.attach(mesh);
  loop(2);
  loop.detach();
  std::vector<Vec3> next(mesh.n_vertices());
  for (int step = 0; step < 3; ++step) {
    for (const auto v : mesh.vertices()) {
      Vec3 sum(0, 0, 0);
      int n = 0;
      for (const auto u : mesh.vv_range(v)) {
        sum += mesh.point(u);
        ++n;
      }
      next[v.idx()] = 0.5 * mesh.point(v) + 0.5 * sum / n;
    }
    for (const auto v : mesh.vertices()) mesh.point(v) = next[v.idx()];
  }
  return mesh;
}

TEST_F(RealQuads, AnimalsOntoSmoothedLoopSubdivisions) {
  // The base mesh's base complex (its patches) onto a surface that none of its vertices lie on.
  const std::map<std::string, int> patches{
      {"cat_cat.obj", 1160}, {"cow_cow.obj", 1258}, {"pig_pig.obj", 940}};
  for (const auto& [name, count] : patches) {
    const PolyMesh quads = load_poly_mesh(dir_ + "/animals_basemesh/" + name);
    const TriMesh target = loop_smoothed(quads);
    const QuadImportResult r = import_quads(quads, &target, {});
    expect_matches_complex(r, name);
    EXPECT_EQ(r.complex.num_patches, count) << name;
  }
}

TEST_F(RealQuads, InspiredQuadMeshesOntoTheirTriangleMesh) {
  const TriMesh target = load_mesh(dir_ + "/inspired_mesh/inspired_mesh.obj");
  for (const char* file : {"inspired_mesh_quads_Conjugate.off", "inspired_mesh_quads_Smooth.off"}) {
    const PolyMesh quads = load_poly_mesh(dir_ + "/inspired_mesh/" + std::string(file));
    const QuadImportResult r = import_quads(quads, &target, {});
    expect_matches_complex(r, file);
    // The staircase boundary makes the base complex one patch per quad.
    EXPECT_EQ(r.complex.num_patches, static_cast<int>(quads.n_faces())) << file;
  }
}

TEST_F(RealQuads, CliTransfersOntoTheTargetsWorkingMesh) {
  // import-quads --onto T writes T's working mesh and the layout on it; validate accepts them
  // and the report gives the target's and the working mesh's sizes.
  const std::string base = dir_ + "/quadwild_joint/joint_rem_p";
  const std::string out = test::temp_dir("import_quads_onto");
  std::string output;
  ASSERT_EQ(test::run_command(test::cli_path() + " import-quads --quads " + base +
                                  "_quadrangulation.obj --onto " + base + ".obj --out " + out,
                              &output),
            0)
      << output;
  EXPECT_NE(output.find("growth"), std::string::npos) << output;
  std::ifstream in(out + "/report.json");
  const std::string report((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(report.find("\"working_mesh\""), std::string::npos) << report;
  EXPECT_NE(report.find("\"input\""), std::string::npos) << report;
  EXPECT_NE(report.find("\"growth\""), std::string::npos) << report;
  ASSERT_EQ(test::run_command(test::cli_path() + " validate --mesh " + out + "/mesh.obj --layout " +
                                  out + "/layout.json",
                              &output),
            0)
      << output;
  EXPECT_NE(output.find("3753 patches"), std::string::npos) << output;
}

TEST_F(RealQuads, InspiredCoarsenedOntoItsTriangleMesh) {
  // The staircase boundary makes almost every vertex a node of the base complex; collapsing its
  // thin chords gives a coarser layout on the (boundary) triangle mesh.
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
  // Without coarsening the whole base complex transfers (one patch per quad).
  const QuadImportResult full = import_quads(quads, &target, {});
  expect_matches_complex(full, "inspired");
  EXPECT_EQ(full.complex.num_patches, 1633);
}

TEST_F(RealQuads, QuadWildPatchesOfTheJointSplitIntoQuads) {
  // QuadWild's own patches of joint_rem_p.obj (25 quads, 12 pentagons), each n-gon split into n
  // quads on the triangle mesh itself: a valid genus-2 layout with one patch per side.
  const std::string base = dir_ + "/quadwild_joint/joint_rem_p";
  const TriMesh mesh = load_mesh(base + ".obj");
  const PatchPartition partition =
      load_quadwild_partition(mesh, base + ".patch", base + ".corners");
  PatchLayoutStats stats;
  const Layout layout = layout_from_partition(mesh, partition, &stats);
  const ValidationResult vr = validate_layout(mesh, layout);
  ASSERT_TRUE(vr.valid()) << (vr.issues.empty() ? "" : format_issue(vr.issues[0]));
  const LayoutTopology topo = build_topology(mesh, layout);
  ASSERT_EQ(stats.partition_patches, static_cast<int>(partition.corners.size()));
  EXPECT_EQ(static_cast<int>(topo.patches.size()), stats.expected_patches);
  int n_centres = 0;
  for (const auto& centres : stats.centres) n_centres += static_cast<int>(centres.size());
  EXPECT_EQ(topo.num_nodes, stats.partition_nodes + stats.partition_arcs + n_centres);
  EXPECT_EQ(topo.num_nodes - topo.num_arcs + static_cast<int>(topo.patches.size()), -2);
  // Every listed corner is a node; every side midpoint joins its two halves and one or two
  // centres on each side (two where a patch needed two centres, valence 4..6); a single centre
  // has one arc per side, two centres have k + 2 arc ends together.
  std::vector<int> node_of_vertex(mesh.n_vertices(), -1);
  for (size_t n = 0; n < layout.nodes.size(); ++n) node_of_vertex[layout.nodes[n].vertex] = n;
  for (const auto& corners : partition.corners)
    for (int v : corners) EXPECT_GE(node_of_vertex[v], 0) << "corner vertex " << v;
  const int first_mid = stats.partition_nodes, first_centre = first_mid + stats.partition_arcs;
  for (int n = first_mid; n < first_centre; ++n) {
    EXPECT_GE(topo.valence[n], 4) << "node " << n;
    EXPECT_LE(topo.valence[n], 6) << "node " << n;
  }
  int two_centres = 0;
  for (int p = 0; p < stats.partition_patches; ++p) {
    const auto& centres = stats.centres[p];
    ASSERT_TRUE(centres.size() == 1 || centres.size() == 2) << "patch " << p;
    int ends = 0;
    for (int c : centres) {
      ends += topo.valence[c];
      // A centre lies inside its patch.
      for (const auto f : mesh.vf_range(VH(layout.nodes[c].vertex)))
        EXPECT_EQ(partition.face_patch[f.idx()], p) << "centre of patch " << p;
    }
    EXPECT_EQ(ends, stats.sides[p] + (centres.size() == 2 ? 2 : 0)) << "patch " << p;
    EXPECT_EQ(stats.quads[p], stats.sides[p] + (centres.size() == 2 ? 1 : 0)) << "patch " << p;
    two_centres += centres.size() == 2;
  }
  EXPECT_LE(two_centres, 3);
  // Every quad lies inside one QuadWild patch.
  std::vector<int> owner(topo.patches.size(), -1);
  for (size_t f = 0; f < mesh.n_faces(); ++f) {
    const int q = topo.face_patch[f];
    ASSERT_GE(q, 0);
    if (owner[q] < 0) owner[q] = partition.face_patch[f];
    EXPECT_EQ(owner[q], partition.face_patch[f]) << "face " << f;
  }
}

TEST(PatchImport, CubeFacesSplitIntoFourQuadsEach) {
  // The six faces of a triangulated cube as patches (corners derived: the 8 vertices where
  // three patches meet): 6 × 4 quads, nodes = 8 corners + 12 side midpoints + 6 centres.
  const TriMesh mesh = triangulate_quads(quad_cube(4), 2);
  PatchPartition partition;
  partition.corners.assign(6, {});
  for (const auto f : mesh.faces()) {
    const Vec3 n = mesh.calc_face_normal(f);
    int axis = 0;
    for (int i = 1; i < 3; ++i)
      if (std::abs(n[i]) > std::abs(n[axis])) axis = i;
    partition.face_patch.push_back(2 * axis + (n[axis] > 0 ? 1 : 0));
  }
  PatchLayoutStats stats;
  const Layout layout = layout_from_partition(mesh, partition, &stats);
  const ValidationResult vr = validate_layout(mesh, layout);
  ASSERT_TRUE(vr.valid()) << (vr.issues.empty() ? "" : format_issue(vr.issues[0]));
  const LayoutTopology topo = build_topology(mesh, layout);
  EXPECT_EQ(stats.partition_nodes, 8);
  EXPECT_EQ(stats.partition_arcs, 12);
  EXPECT_EQ(stats.expected_patches, 24);
  EXPECT_EQ(static_cast<int>(topo.patches.size()), 24);
  EXPECT_EQ(topo.num_nodes, 26);
  EXPECT_EQ(topo.num_arcs, 48);
  for (int n = 0; n < 8; ++n) EXPECT_EQ(topo.valence[n], 3) << "corner " << n;
  for (int n = 8; n < 26; ++n) EXPECT_EQ(topo.valence[n], 4) << "node " << n;
  // Each quad lies in one cube face; each face holds four.
  std::vector<int> owner(topo.patches.size(), -1), count(6, 0);
  for (size_t f = 0; f < mesh.n_faces(); ++f) {
    const int q = topo.face_patch[f];
    if (owner[q] < 0) owner[q] = partition.face_patch[f], ++count[owner[q]];
    EXPECT_EQ(owner[q], partition.face_patch[f]);
  }
  for (int c : count) EXPECT_EQ(c, 4);
}

TEST(PatchImport, RandomPartitionsGiveValidLayoutsOrClearErrors) {
  // Grown random partitions of a triangulated cube (patches of any shape and side count, some
  // not disks): the result is a valid layout with one quad per side (k + 1 with two centres),
  // or an InvalidInputError (anything else fails the test).
  const TriMesh mesh = triangulate_quads(quad_cube(6), 2);
  const int nf = static_cast<int>(mesh.n_faces());
  int built = 0;
  for (unsigned seed = 1; seed <= 40; ++seed) {
    const int n_patches = 3 + static_cast<int>(seed % 9);
    PatchPartition partition;
    partition.corners.assign(n_patches, {});
    partition.face_patch.assign(nf, -1);
    std::vector<int> queue;
    unsigned state = seed * 2654435761u;
    auto next = [&] { return state = state * 1664525u + 1013904223u; };
    for (int p = 0; p < n_patches; ++p) {
      int f = static_cast<int>(next() % nf);
      while (partition.face_patch[f] >= 0) f = (f + 1) % nf;
      partition.face_patch[f] = p;
      queue.push_back(f);
    }
    for (size_t head = 0; head < queue.size(); ++head) {
      const int f = queue[head];
      for (const auto g : mesh.ff_range(OpenMesh::FaceHandle(f))) {
        if (partition.face_patch[g.idx()] >= 0) continue;
        partition.face_patch[g.idx()] = partition.face_patch[f];
        queue.push_back(g.idx());
      }
    }
    try {
      PatchLayoutStats stats;
      const Layout layout = layout_from_partition(mesh, partition, &stats);
      ASSERT_TRUE(validate_layout(mesh, layout).valid()) << "seed " << seed;
      EXPECT_EQ(static_cast<int>(build_topology(mesh, layout).patches.size()),
                stats.expected_patches)
          << "seed " << seed;
      ++built;
    } catch (const InvalidInputError&) {
      // e.g. a side of a single edge or a patch whose interior is pinched: named in the message
    }
  }
  EXPECT_GE(built, 10);  // 20 of the 40 at the time of writing
}

TEST(PatchImport, MalformedPartitionFilesAreClearErrors) {
  const std::string dir = test::temp_dir("patch_import_bad");
  const TriMesh mesh = triangulate_quads(quad_cube(2), 2);
  auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir + "/" + name) << text;
    return dir + "/" + name;
  };
  const std::string corners = write("c.corners", "1\n3\n0 1 2\n");
  // Wrong face count, patch id out of range, vertex out of range, missing file.
  EXPECT_THROW(load_quadwild_partition(mesh, write("a.patch", "3\n0 0 0\n"), corners),
               InvalidInputError);
  std::string ids = std::to_string(mesh.n_faces()) + "\n";
  for (size_t f = 0; f < mesh.n_faces(); ++f) ids += (f == 5 ? "7\n" : "0\n");
  EXPECT_THROW(load_quadwild_partition(mesh, write("b.patch", ids), corners), InvalidInputError);
  EXPECT_THROW(
      load_quadwild_partition(mesh, write("b.patch", ids), write("d.corners", "1\n3\n0 1 99999\n")),
      InvalidInputError);
  EXPECT_THROW(load_quadwild_partition(mesh, dir + "/missing.patch", corners), InvalidInputError);
  // A corners file announcing more patches than it holds.
  EXPECT_THROW(
      load_quadwild_partition(mesh, write("b.patch", ids), write("e.corners", "2\n3\n0 1 2\n")),
      InvalidInputError);
  // A single patch covering the closed cube is not a disk.
  PatchPartition one;
  one.face_patch.assign(mesh.n_faces(), 0);
  one.corners = {{0, 1, 2}};
  try {
    layout_from_partition(mesh, one);
    FAIL() << "expected InvalidInputError";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("patch 0"), std::string::npos) << e.what();
  }
}

TEST_F(RealQuads, JointCoarsenedOnItsOwnQuads) {
  // The spiralling base complex of the QuadWild joint, coarsened by chord collapse, transferred
  // onto a working mesh of the triangulated quad mesh: a valid genus-2 layout with fewer patches.
  QuadImportOptions options;
  options.coarsen = 4;
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
