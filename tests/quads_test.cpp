// Block-structured quad mesh and its exports (issue #8).
#include "core/extract/quads.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "core/base/atomic_file.h"
#include "core/base/errors.h"
#include "core/layout/layout_io.h"
#include "core/mesh/closest_point.h"
#include "core/mesh/mesh_io.h"
#include "core/pipeline/pipeline.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

struct QuadRun {
  std::unique_ptr<Pipeline> pipeline;
  Extraction extraction;
  QuadMesh quads;
};

QuadRun run_quads(test::MeshAndLayout in, QuadMeshOptions options) {
  QuadRun r;
  r.pipeline = std::make_unique<Pipeline>(std::move(in.mesh), std::move(in.layout));
  r.pipeline->compute_field();
  r.pipeline->compute_parameterization();
  r.extraction = r.pipeline->extract();
  for (const auto& p : r.extraction.problems) ADD_FAILURE() << "extraction: " << p;
  r.quads = build_quad_mesh(*r.pipeline, r.extraction, options);
  return r;
}

Vec3 vec(const std::array<double, 3>& a) {
  return Vec3(a[0], a[1], a[2]);
}

// Euler characteristic of the input surface.
int surface_euler(const TriMesh& mesh) {
  return static_cast<int>(mesh.n_vertices()) - static_cast<int>(mesh.n_edges()) +
         static_cast<int>(mesh.n_faces());
}

// Undirected edge → number of quads using it; directed edge → count (orientation check).
struct EdgeCounts {
  std::map<std::pair<int, int>, int> undirected, directed;
};
EdgeCounts count_edges(const QuadMesh& qm) {
  EdgeCounts c;
  for (const auto& q : qm.quads)
    for (int k = 0; k < 4; ++k) {
      const int a = q[k], b = q[(k + 1) % 4];
      ++c.directed[{a, b}];
      ++c.undirected[{std::min(a, b), std::max(a, b)}];
    }
  return c;
}

// Checks shared by every input: no degenerate quad, every vertex on the surface and used,
// quads oriented like the surface, quad count = Σ m·n, counts agree along poly-chords.
void expect_sound(const QuadRun& r) {
  const QuadMesh& qm = r.quads;
  const TriMesh& mesh = r.pipeline->mesh();
  const double diag = r.pipeline->geometry().bbox_diagonal;
  ASSERT_GT(qm.quads.size(), 0u);
  for (const auto& w : qm.warnings) ADD_FAILURE() << "warning: " << w;
  // Σ m·n, m = ⌈w/q⌉ at least, opposite sides equal.
  long total = 0;
  const auto& topo = r.pipeline->topology();
  for (const auto& qp : qm.patches) {
    EXPECT_TRUE(qp.ok) << "patch " << qp.patch << ": " << qp.failure;
    if (!qp.ok) continue;
    total += static_cast<long>(qp.grid[0]) * qp.grid[1];
    EXPECT_EQ(qp.num_quads, qp.grid[0] * qp.grid[1]);
    EXPECT_GE(qp.grid[0], std::ceil(qp.size[0] / qm.quad_size - 1e-6));
    EXPECT_GE(qp.grid[1], std::ceil(qp.size[1] / qm.quad_size - 1e-6));
    const auto& d = topo.patches[qp.patch].darts;
    EXPECT_EQ(qm.arc_segments[d[0] >> 1], qm.arc_segments[d[2] >> 1]);
    EXPECT_EQ(qm.arc_segments[d[1] >> 1], qm.arc_segments[d[3] >> 1]);
  }
  EXPECT_EQ(static_cast<long>(qm.quads.size()), total);
  EXPECT_EQ(count_quads(topo, r.extraction, qm.quad_size), total);
  // Every vertex used and on the surface.
  std::vector<int> used(qm.vertices.size(), 0);
  for (const auto& q : qm.quads)
    for (int v : q) ++used[v];
  for (size_t v = 0; v < used.size(); ++v) EXPECT_GT(used[v], 0) << "unused vertex " << v;
  const ClosestPointTree tree(mesh);
  double worst = 0;
  for (const auto& x : qm.vertices) worst = std::max(worst, tree.closest(vec(x)).distance);
  EXPECT_LT(worst, 1e-6 * diag) << "quad mesh vertex off the surface";
  // No degenerate quad; normals agree with the surface normal.
  int degenerate = 0, flipped = 0;
  for (const auto& q : qm.quads) {
    const Vec3 p0 = vec(qm.vertices[q[0]]), p1 = vec(qm.vertices[q[1]]),
               p2 = vec(qm.vertices[q[2]]), p3 = vec(qm.vertices[q[3]]);
    const Vec3 n = 0.5 * ((p1 - p0) % (p2 - p0) + (p2 - p0) % (p3 - p0));
    const double a0 = ((p1 - p0) % (p2 - p0)).norm(), a1 = ((p2 - p0) % (p3 - p0)).norm();
    const double a2 = ((p2 - p1) % (p3 - p1)).norm(), a3 = ((p3 - p1) % (p0 - p1)).norm();
    if (std::min({a0, a1, a2, a3}) <= 1e-12 * diag * diag) ++degenerate;
    const auto cp = tree.closest(0.25 * (p0 + p1 + p2 + p3));
    const auto fv = r.pipeline->geometry().face_vertices[cp.face];
    const Vec3 fn = r.pipeline->geometry().face_normal[cp.face];
    (void)fv;
    if ((n | fn) <= 0) ++flipped;
  }
  EXPECT_EQ(degenerate, 0);
  EXPECT_EQ(flipped, 0) << "quads must be counter-clockwise seen from outside";
}

// Closed input: closed and manifold (each edge in exactly two quads, once in each direction),
// same Euler characteristic as the surface.
void expect_closed(const QuadRun& r) {
  const auto c = count_edges(r.quads);
  int bad = 0, misoriented = 0;
  for (const auto& [e, n] : c.undirected) bad += n != 2;
  for (const auto& [e, n] : c.directed) misoriented += n != 1;
  EXPECT_EQ(bad, 0) << "edges not in exactly two quads";
  EXPECT_EQ(misoriented, 0) << "inconsistent quad orientation";
  // Vertex manifoldness: the quads around each vertex form one cycle.
  std::vector<std::vector<std::pair<int, int>>> fan(r.quads.vertices.size());
  for (const auto& q : r.quads.quads)
    for (int k = 0; k < 4; ++k) fan[q[k]].push_back({q[(k + 1) % 4], q[(k + 3) % 4]});
  int nonmanifold = 0;
  for (const auto& f : fan) {
    if (f.empty()) continue;
    std::map<int, int> next;  // out-neighbour → in-neighbour of the next quad
    for (const auto& [a, b] : f) next[a] = b;
    size_t steps = 0;
    int cur = f[0].first;
    do {
      auto it = std::find_if(f.begin(), f.end(), [&](auto& e) { return e.second == cur; });
      if (it == f.end()) break;
      cur = it->first;
      ++steps;
    } while (cur != f[0].first && steps <= f.size());
    nonmanifold += steps != f.size();
  }
  EXPECT_EQ(nonmanifold, 0);
  const long chi = static_cast<long>(r.quads.vertices.size()) -
                   static_cast<long>(c.undirected.size()) + static_cast<long>(r.quads.quads.size());
  EXPECT_EQ(chi, surface_euler(r.pipeline->mesh()));
}

TEST(QuadMesh, CubeSphereIsClosedManifold) {
  QuadMeshOptions opt;
  opt.quad_size = 0.2;
  const QuadRun r = run_quads(test::cube_sphere(8), opt);
  expect_sound(r);
  expect_closed(r);
  EXPECT_EQ(r.quads.gridded_patches(), 6);
}

TEST(QuadMesh, CoarseQuadSizeGivesOneQuadPerPatch) {
  QuadMeshOptions opt;
  opt.quad_size = 100;
  const QuadRun r = run_quads(test::cube_sphere(6), opt);
  expect_sound(r);
  expect_closed(r);
  EXPECT_EQ(r.quads.quads.size(), 6u);
  EXPECT_EQ(r.quads.vertices.size(), 8u);
}

TEST(QuadMesh, AnisotropicEllipsoidCountsFollowPolyChords) {
  QuadMeshOptions opt;
  opt.quad_size = 0.15;
  const QuadRun r = run_quads(test::cube_sphere(10, Vec3(1.5, 1.0, 0.7)), opt);
  expect_sound(r);
  expect_closed(r);
  // Different grid sizes in different directions.
  std::set<int> sizes;
  for (const auto& qp : r.quads.patches) sizes.insert(qp.grid[0]), sizes.insert(qp.grid[1]);
  EXPECT_GT(sizes.size(), 1u);
}

TEST(QuadMesh, TorusIsClosedManifold) {
  QuadMeshOptions opt;
  opt.quad_size = 0.3;
  const QuadRun r = run_quads(test::torus_grid(32, 16, 4, 2), opt);
  expect_sound(r);
  expect_closed(r);
  EXPECT_EQ(surface_euler(r.pipeline->mesh()), 0);
}

TEST(QuadMesh, Genus2PolycubeIsClosedManifold) {
  QuadMeshOptions opt;
  opt.quad_size = 0.3;
  const QuadRun r = run_quads(test::genus2_polycube(3), opt);
  expect_sound(r);
  expect_closed(r);
  EXPECT_EQ(surface_euler(r.pipeline->mesh()), -2);
  // Flat isometric patches of unit size: exactly ⌈1/0.3⌉ = 4 quads per side, and the grid
  // points (interior ones located in the charts) form exact squares of side 1/4.
  for (const auto& qp : r.quads.patches) {
    EXPECT_EQ(qp.grid[0], 4);
    EXPECT_EQ(qp.grid[1], 4);
  }
  double worst = 0;
  for (const auto& q : r.quads.quads)
    for (int k = 0; k < 4; ++k)
      worst = std::max(
          worst,
          std::abs((vec(r.quads.vertices[q[k]]) - vec(r.quads.vertices[q[(k + 1) % 4]])).norm() -
                   0.25));
  EXPECT_LT(worst, 1e-6) << "grid points not where the isometric chart puts them";
}

TEST(QuadMesh, PatchesOfFailedArcsAreSkippedWithWarnings) {
  QuadMeshOptions opt;
  opt.quad_size = 0.2;
  QuadRun r = run_quads(test::cube_sphere(8), opt);
  r.extraction.arcs[0].ok = false;
  r.extraction.arcs[0].failure = "simulated";
  const QuadMesh qm = build_quad_mesh(*r.pipeline, r.extraction, opt);
  EXPECT_EQ(qm.gridded_patches(), 4);
  int skipped = 0;
  for (const auto& qp : qm.patches) skipped += !qp.ok && !qp.failure.empty();
  EXPECT_EQ(skipped, 2);
  EXPECT_EQ(qm.warnings.size(), 3u);  // the arc and its two patches
  EXPECT_TRUE(qm.arc_vertices[0].empty());
  // The rest stays an oriented manifold (with boundary around the hole).
  const auto c = count_edges(qm);
  int over = 0, misoriented = 0, boundary = 0;
  for (const auto& [e, n] : c.undirected) over += n > 2, boundary += n == 1;
  for (const auto& [e, n] : c.directed) misoriented += n != 1;
  EXPECT_EQ(over, 0);
  EXPECT_EQ(misoriented, 0);
  EXPECT_GT(boundary, 0);
}

// Distance from p to segment ab.
double segment_distance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double t = std::clamp(((p - a) | ab) / std::max(ab.sqrnorm(), 1e-300), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

TEST(QuadMesh, DiskBoundaryEdgesLieOnSurfaceBoundary) {
  QuadMeshOptions opt;
  opt.quad_size = 0.7;
  const QuadRun r = run_quads(test::disk_grid(8, 6, 2, 3), opt);
  expect_sound(r);
  const TriMesh& mesh = r.pipeline->mesh();
  std::vector<std::pair<Vec3, Vec3>> border;
  for (auto e : mesh.edges())
    if (mesh.is_boundary(e)) {
      const auto h = mesh.halfedge_handle(e, 0);
      border.push_back(
          {mesh.point(mesh.from_vertex_handle(h)), mesh.point(mesh.to_vertex_handle(h))});
    }
  const auto c = count_edges(r.quads);
  int boundary_edges = 0, off = 0, bad = 0;
  double boundary_length = 0;
  for (const auto& [e, n] : c.undirected) {
    bad += n > 2;
    if (n != 1) continue;
    ++boundary_edges;
    const Vec3 a = vec(r.quads.vertices[e.first]), b = vec(r.quads.vertices[e.second]);
    boundary_length += (b - a).norm();
    for (const Vec3& p : {a, b, 0.5 * (a + b)}) {
      double d = 1e300;
      for (const auto& [s, t] : border) d = std::min(d, segment_distance(p, s, t));
      off += d > 1e-9;
    }
  }
  EXPECT_EQ(bad, 0);
  EXPECT_GT(boundary_edges, 0);
  EXPECT_EQ(off, 0) << "quad mesh boundary edge not on the surface boundary";
  EXPECT_NEAR(boundary_length, 2 * (8 + 6), 1e-6) << "the boundary must be covered once";
  // Disk: χ = 1.
  const long chi = static_cast<long>(r.quads.vertices.size()) -
                   static_cast<long>(c.undirected.size()) + static_cast<long>(r.quads.quads.size());
  EXPECT_EQ(chi, 1);
}

TEST(QuadMesh, QuadCountTargetsAboutNQuads) {
  QuadMeshOptions opt;
  opt.quad_count = 600;
  const QuadRun r = run_quads(test::cube_sphere(8), opt);
  expect_sound(r);
  const double n = static_cast<double>(r.quads.quads.size());
  EXPECT_GT(n, 0.75 * 600);
  EXPECT_LT(n, 1.25 * 600);
  EXPECT_THROW(build_quad_mesh(*r.pipeline, r.extraction, QuadMeshOptions{}), InvalidInputError);
}

TEST(QuadMesh, ExportsAreReadableAndConsistent) {
  QuadMeshOptions opt;
  opt.quad_size = 0.25;
  const QuadRun r = run_quads(test::cube_sphere(8), opt);
  const std::string dir = test::temp_dir("quads_exports");
  const Layout layout = r.pipeline->output_layout();
  write_quad_exports(r.quads, layout, r.extraction, dir);
  // quads.obj through OpenMesh's reader.
  const PolyMesh pm = load_poly_mesh(dir + "/quads.obj");
  EXPECT_EQ(pm.n_vertices(), r.quads.vertices.size());
  EXPECT_EQ(pm.n_faces(), r.quads.quads.size());
  for (auto f : pm.faces()) EXPECT_EQ(pm.valence(f), 4u);
  // One group per patch, and the vt lines.
  std::ifstream obj(dir + "/quads.obj");
  std::string line;
  int groups = 0, vts = 0;
  while (std::getline(obj, line)) {
    groups += line.rfind("g patch_", 0) == 0;
    vts += line.rfind("vt ", 0) == 0;
  }
  EXPECT_EQ(groups, 6);
  EXPECT_GT(vts, 0);
  // patches.json: one entry per patch, 4 curves from corner node to corner node.
  const auto j = nlohmann::json::parse(read_file(dir + "/patches.json"));
  ASSERT_EQ(j["patches"].size(), r.pipeline->topology().patches.size());
  const double tol = 1e-9 * r.pipeline->geometry().bbox_diagonal;
  for (const auto& p : j["patches"]) {
    ASSERT_EQ(p["curves"].size(), 4u);
    ASSERT_EQ(p["nodes"].size(), 4u);
    const int m = p["grid"][0], n = p["grid"][1];
    EXPECT_EQ(p["quads"]["count"].get<int>(), m * n);
    for (int k = 0; k < 4; ++k) {
      const auto& curve = p["curves"][k];
      ASSERT_GE(curve.size(), 2u);
      const int node = layout.node_index(p["nodes"][k].get<int>());
      const int node_next = layout.node_index(p["nodes"][(k + 1) % 4].get<int>());
      const Vec3 x0 =
          r.pipeline->mesh().point(r.pipeline->mesh().vertex_handle(layout.nodes[node].vertex));
      const Vec3 x1 = r.pipeline->mesh().point(
          r.pipeline->mesh().vertex_handle(layout.nodes[node_next].vertex));
      const auto& a = curve.front();
      const auto& b = curve.back();
      EXPECT_LT((Vec3(a[0], a[1], a[2]) - x0).norm(), tol);
      EXPECT_LT((Vec3(b[0], b[1], b[2]) - x1).norm(), tol);
    }
  }
  // layout_curves.obj: one polyline per arc.
  std::ifstream curves(dir + "/layout_curves.obj");
  int polylines = 0;
  while (std::getline(curves, line)) polylines += line.rfind("l ", 0) == 0;
  EXPECT_EQ(polylines, r.pipeline->topology().num_arcs);
}

TEST(QuadMesh, CliWritesQuadFiles) {
  const std::string dir = test::temp_dir("quads_cli");
  const auto in = test::cube_sphere(6);
  test::write_obj(in.mesh, dir + "/m.obj");
  // The layout via the library writer.
  std::string out;
  const std::string layout_path = dir + "/m.layout.json";
  save_layout(in.layout, layout_path, &in.mesh);
  const int rc =
      test::run_command(test::cli_path() + " -q optimize --mesh " + dir + "/m.obj" + " --layout " +
                            layout_path + " --out " + dir + "/out --no-node-opt --quad-count 150",
                        &out);
  ASSERT_EQ(rc, 0) << out;
  for (const char* f : {"quads.obj", "patches.json", "layout_curves.obj", "report.json"})
    EXPECT_TRUE(std::filesystem::exists(dir + "/out/" + f)) << f;
  const PolyMesh pm = load_poly_mesh(dir + "/out/quads.obj");
  EXPECT_GT(pm.n_faces(), 75u);
  EXPECT_LT(pm.n_faces(), 300u);
}

}  // namespace
}  // namespace qs
