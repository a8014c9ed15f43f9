// Block-structured quad mesh and its exports (issue #8).
#include "core/extract/quads.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <numeric>
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
  // layout_curves.obj: one group per arc (checked in detail by LayoutCurves.* below).
  std::ifstream curves(dir + "/layout_curves.obj");
  int arc_groups = 0;
  while (std::getline(curves, line)) arc_groups += line.rfind("g arc_", 0) == 0;
  EXPECT_EQ(arc_groups, r.pipeline->topology().num_arcs);
}

// An OBJ reader written for these tests, independent of the writers: vertices, texture
// coordinates, and per group (g) its line segments (an `l` of k vertices is k − 1 segments) and
// faces as (v, vt) corners. Indices 0-based; negative (relative) indices resolved.
struct ObjGroup {
  std::vector<std::array<long, 2>> segments;
  std::vector<int> line_sizes;  //!< vertices per `l` record
  std::vector<std::vector<std::array<long, 2>>> faces;
};
struct ObjFile {
  std::vector<std::array<double, 3>> v;
  std::vector<std::array<double, 2>> vt;
  std::vector<std::string> group_order;
  std::map<std::string, ObjGroup> groups;
};
ObjFile read_obj_independently(const std::string& path) {
  ObjFile obj;
  std::ifstream in(path);
  EXPECT_TRUE(in) << path;
  std::string line, tag, group = "default";
  auto resolve = [](long i, size_t count) { return i > 0 ? i - 1 : static_cast<long>(count) + i; };
  while (std::getline(in, line)) {
    std::istringstream ss(line);
    if (!(ss >> tag) || tag[0] == '#') continue;
    if (tag == "v") {
      std::array<double, 3> x{};
      ss >> x[0] >> x[1] >> x[2];
      obj.v.push_back(x);
    } else if (tag == "vt") {
      std::array<double, 2> t{};
      ss >> t[0] >> t[1];
      obj.vt.push_back(t);
    } else if (tag == "g" || tag == "o") {
      if (tag == "o") continue;  // one object per file here; groups name the parts
      ss >> group;
      if (!obj.groups.count(group)) obj.group_order.push_back(group);
      obj.groups[group];
    } else if (tag == "l" || tag == "f") {
      std::vector<std::array<long, 2>> corners;
      std::string c;
      while (ss >> c) {
        const size_t slash = c.find('/');
        const long vi = resolve(std::stol(c.substr(0, slash)), obj.v.size());
        long ti = -1;
        if (slash != std::string::npos && slash + 1 < c.size() && c[slash + 1] != '/')
          ti = resolve(std::stol(c.substr(slash + 1)), obj.vt.size());
        corners.push_back({vi, ti});
      }
      ObjGroup& g = obj.groups[group];
      if (tag == "l") {
        g.line_sizes.push_back(static_cast<int>(corners.size()));
        for (size_t i = 0; i + 1 < corners.size(); ++i)
          g.segments.push_back({corners[i][0], corners[i + 1][0]});
      } else {
        g.faces.push_back(std::move(corners));
      }
    }
  }
  return obj;
}

double dist(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

// The layout_curves.obj checks: every arc's group is a chain of 2-vertex line records along its
// traced polyline, the edges of all groups are Σ (points − 1), and an arc's end vertices are its
// nodes' vertices, one per node, shared by all arcs there (none for ends off a node).
void expect_layout_curves(const std::string& path, const Layout& layout, const Extraction& ex,
                          double tol) {
  const ObjFile obj = read_obj_independently(path);
  long want_edges = 0, got_edges = 0;
  for (const auto& t : ex.arcs)
    if (t.polyline.size() >= 2) want_edges += static_cast<long>(t.polyline.size()) - 1;
  for (const auto& [name, g] : obj.groups) {
    got_edges += static_cast<long>(g.segments.size());
    for (int n : g.line_sizes)
      EXPECT_EQ(n, 2) << name << ": an `l` record with " << n << " vertices";
  }
  EXPECT_EQ(got_edges, want_edges) << "line segments in " << path;
  std::map<int, std::set<long>> node_vertices;  // node index → vertex indices at its arc ends
  std::set<long> end_vertices_off_nodes;
  for (size_t a = 0; a < ex.arcs.size(); ++a) {
    const auto& poly = ex.arcs[a].polyline;
    const std::string name = "arc_" + std::to_string(layout.arcs[a].id);
    ASSERT_TRUE(obj.groups.count(name)) << name;
    const auto& seg = obj.groups.at(name).segments;
    ASSERT_EQ(seg.size() + 1, poly.size()) << name;
    for (size_t i = 0; i < seg.size(); ++i) {
      ASSERT_GE(seg[i][0], 0);
      ASSERT_GE(seg[i][1], 0);
      ASSERT_LT(seg[i][0], static_cast<long>(obj.v.size()));
      ASSERT_LT(seg[i][1], static_cast<long>(obj.v.size()));
      if (i + 1 < seg.size()) {
        EXPECT_EQ(seg[i][1], seg[i + 1][0]) << name << " is not a chain";
      }
      EXPECT_LT(dist(obj.v[seg[i][0]], poly[i]), tol) << name << " point " << i;
    }
    EXPECT_LT(dist(obj.v[seg.back()[1]], poly.back()), tol) << name << " end";
    node_vertices[layout.node_index(layout.arcs[a].from)].insert(seg.front()[0]);
    if (layout.arcs[a].to >= 0 && ex.arcs[a].ok)
      node_vertices[layout.node_index(layout.arcs[a].to)].insert(seg.back()[1]);
    else
      end_vertices_off_nodes.insert(seg.back()[1]);
  }
  std::set<long> all_node_vertices;
  for (const auto& [node, vs] : node_vertices) {
    EXPECT_EQ(vs.size(), 1u) << "node " << layout.nodes[node].id << " has " << vs.size()
                             << " vertices";
    all_node_vertices.insert(vs.begin(), vs.end());
  }
  EXPECT_EQ(all_node_vertices.size(), node_vertices.size()) << "two nodes share a vertex";
  for (long v : end_vertices_off_nodes)
    EXPECT_FALSE(all_node_vertices.count(v)) << "an arc end off its node uses a node vertex";
  // The node group lists the node vertices.
  ASSERT_TRUE(obj.groups.count("nodes") || node_vertices.empty());
}

// Connected pieces of the curve network (vertices joined by segments).
int curve_pieces(const ObjFile& obj) {
  std::vector<long> parent(obj.v.size());
  std::iota(parent.begin(), parent.end(), 0L);
  auto find = [&](long x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  std::set<long> used;
  for (const auto& [name, g] : obj.groups)
    for (const auto& s : g.segments) {
      parent[find(s[0])] = find(s[1]);
      used.insert(s[0]);
      used.insert(s[1]);
    }
  std::set<long> roots;
  for (long v : used) roots.insert(find(v));
  return static_cast<int>(roots.size());
}

TEST(LayoutCurves, ArcsAreTwoVertexLinesSharingNodeVertices) {
  QuadMeshOptions opt;
  opt.quad_size = 0.25;
  const QuadRun r = run_quads(test::cube_sphere(8), opt);
  const std::string dir = test::temp_dir("layout_curves");
  const Layout layout = r.pipeline->output_layout();
  write_layout_curves_obj(layout, r.extraction, dir + "/layout_curves.obj");
  const double tol = 1e-9 * r.pipeline->geometry().bbox_diagonal;
  expect_layout_curves(dir + "/layout_curves.obj", layout, r.extraction, tol);
  // The cube's 12 arcs between 8 nodes make one connected network.
  const ObjFile obj = read_obj_independently(dir + "/layout_curves.obj");
  EXPECT_EQ(curve_pieces(obj), 1);
  EXPECT_EQ(obj.groups.at("nodes").segments.size(), 0u);
}

TEST(LayoutCurves, FailedArcEndsOnItsOwnVertex) {
  QuadMeshOptions opt;
  opt.quad_size = 0.25;
  QuadRun r = run_quads(test::cube_sphere(6), opt);
  // Arc 0 stopped short of its end node: its end is a vertex of its own.
  r.extraction.arcs[0].ok = false;
  r.extraction.arcs[0].polyline.pop_back();
  const std::string dir = test::temp_dir("layout_curves_failed");
  const Layout layout = r.pipeline->output_layout();
  write_layout_curves_obj(layout, r.extraction, dir + "/layout_curves.obj");
  expect_layout_curves(dir + "/layout_curves.obj", layout, r.extraction,
                       1e-9 * r.pipeline->geometry().bbox_diagonal);
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

// Per group patch_<id> of a quads.obj: the bounding box of its texture coordinates and its
// faces as UV quads.
struct UvPatch {
  std::array<double, 4> box{1e300, 1e300, -1e300, -1e300};  //!< u0, v0, u1, v1
  std::vector<std::array<std::array<double, 2>, 4>> quads;
};
std::map<int, UvPatch> uv_patches(const ObjFile& obj) {
  std::map<int, UvPatch> out;
  for (const auto& [name, g] : obj.groups) {
    if (name.rfind("patch_", 0) != 0) continue;
    UvPatch& p = out[std::stoi(name.substr(6))];
    for (const auto& f : g.faces) {
      EXPECT_EQ(f.size(), 4u);
      std::array<std::array<double, 2>, 4> q{};
      for (size_t c = 0; c < 4 && c < f.size(); ++c) {
        EXPECT_GE(f[c][1], 0) << name << ": a corner without vt";
        if (f[c][1] < 0) continue;
        q[c] = obj.vt[f[c][1]];
        p.box = {std::min(p.box[0], q[c][0]), std::min(p.box[1], q[c][1]),
                 std::max(p.box[2], q[c][0]), std::max(p.box[3], q[c][1])};
      }
      p.quads.push_back(q);
    }
  }
  return out;
}

// Whether two UV triangles overlap with positive area (separating axis test: no edge normal
// of either triangle separates them by more than eps).
using Tri2 = std::array<std::array<double, 2>, 3>;
bool triangles_overlap(const Tri2& a, const Tri2& b, double eps = 1e-12) {
  for (const Tri2* t : {&a, &b})
    for (int e = 0; e < 3; ++e) {
      const auto& p = (*t)[e];
      const auto& q = (*t)[(e + 1) % 3];
      const double nx = q[1] - p[1], ny = p[0] - q[0];
      double amin = 1e300, amax = -1e300, bmin = 1e300, bmax = -1e300;
      for (const auto& x : a) {
        const double d = nx * x[0] + ny * x[1];
        amin = std::min(amin, d), amax = std::max(amax, d);
      }
      for (const auto& x : b) {
        const double d = nx * x[0] + ny * x[1];
        bmin = std::min(bmin, d), bmax = std::max(bmax, d);
      }
      const double scale = std::max(std::hypot(nx, ny), 1e-300);
      if (amax <= bmin + eps * scale || bmax <= amin + eps * scale) return false;
    }
  return true;
}

// Pairs of faces of different patches whose UV triangles overlap, over up to `per_patch` quads
// of each patch (spread over the patch).
int overlapping_uv_faces(const std::map<int, UvPatch>& patches, size_t per_patch) {
  std::vector<std::pair<int, Tri2>> tris;
  for (const auto& [id, p] : patches) {
    const size_t stride = std::max<size_t>(1, p.quads.size() / per_patch);
    for (size_t k = 0; k < p.quads.size(); k += stride) {
      const auto& q = p.quads[k];
      tris.push_back({id, Tri2{q[0], q[1], q[2]}});
      tris.push_back({id, Tri2{q[0], q[2], q[3]}});
    }
  }
  int overlaps = 0;
  for (size_t i = 0; i < tris.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      overlaps +=
          tris[i].first != tris[j].first && triangles_overlap(tris[i].second, tris[j].second);
  return overlaps;
}

TEST(QuadsObj, PackedAtlasIsNonOverlappingAspectCorrectAndUniform) {
  QuadMeshOptions opt;
  opt.quad_size = 0.15;
  const QuadRun r = run_quads(test::cube_sphere(10, Vec3(1.5, 1.0, 0.7)), opt);
  const QuadMesh& qm = r.quads;
  ASSERT_EQ(qm.gridded_patches(), 6);
  const std::string dir = test::temp_dir("quads_atlas");
  write_quads_obj(qm, dir + "/per_patch.obj");
  UvAtlasOptions packed;
  packed.layout = UvAtlasLayout::kPacked;
  write_quads_obj(qm, dir + "/packed.obj", packed);
  const ObjFile a = read_obj_independently(dir + "/per_patch.obj");
  const ObjFile b = read_obj_independently(dir + "/packed.obj");
  ASSERT_EQ(a.vt.size(), b.vt.size());
  const auto pa = uv_patches(a), pb = uv_patches(b);
  ASSERT_EQ(pb.size(), 6u);
  // The per-patch layout: every patch on [0,1]², so the patches overlap (the check can fail).
  for (const auto& [id, p] : pa) EXPECT_EQ(p.box, (std::array<double, 4>{0, 0, 1, 1})) << id;
  EXPECT_GT(overlapping_uv_faces(pa, 40), 0);
  // Packed: inside [0,1]², aspect w/h, one scale, disjoint rectangles a gutter apart.
  for (const auto& t : b.vt) {
    EXPECT_GE(std::min(t[0], t[1]), 0.0);
    EXPECT_LE(std::max(t[0], t[1]), 1.0);
  }
  std::set<double> aspects;
  double scale = 0, area = 0;
  for (const auto& [id, p] : pb) {
    const auto& size = qm.patches[id].size;
    const double du = p.box[2] - p.box[0], dv = p.box[3] - p.box[1];
    ASSERT_GT(du, 0);
    ASSERT_GT(dv, 0);
    EXPECT_NEAR(du / dv, size[0] / size[1], 1e-9 * size[0] / size[1]) << "patch " << id;
    if (scale == 0) scale = du / size[0];
    EXPECT_NEAR(du / size[0], scale, 1e-9 * scale) << "patch " << id;
    EXPECT_NEAR(dv / size[1], scale, 1e-9 * scale) << "patch " << id;
    aspects.insert(std::round(size[0] / size[1] * 1e6));
    area += du * dv;
  }
  EXPECT_GT(aspects.size(), 1u) << "the test needs patches of different aspect ratios";
  EXPECT_GT(area, 0.5) << "the atlas should use most of [0,1]²";
  for (auto i = pb.begin(); i != pb.end(); ++i)
    for (auto j = std::next(i); j != pb.end(); ++j) {
      const auto &x = i->second.box, &y = j->second.box;
      const double gap = std::max({y[0] - x[2], x[0] - y[2], y[1] - x[3], x[1] - y[3]});
      EXPECT_GE(gap, packed.gutter - 1e-12) << "patches " << i->first << " and " << j->first;
    }
  EXPECT_EQ(overlapping_uv_faces(pb, 40), 0);
  // The same patch coordinates: packed = rectangle corner + per-patch coordinate · extent.
  for (const auto& [id, p] : pb) {
    const auto& g = b.groups.at("patch_" + std::to_string(id));
    for (const auto& f : g.faces)
      for (const auto& c : f) {
        const auto &t = b.vt[c[1]], &s = a.vt[c[1]];
        EXPECT_NEAR(t[0], p.box[0] + s[0] * (p.box[2] - p.box[0]), 1e-12);
        EXPECT_NEAR(t[1], p.box[1] + s[1] * (p.box[3] - p.box[1]), 1e-12);
      }
  }
}

TEST(QuadsObj, CliPackedAtlas) {
  const std::string dir = test::temp_dir("quads_cli_atlas");
  const auto in = test::cube_sphere(6, Vec3(1.4, 1.0, 0.8));
  test::write_obj(in.mesh, dir + "/m.obj");
  save_layout(in.layout, dir + "/m.layout.json", &in.mesh);
  const std::string base = test::cli_path() + " -q optimize --mesh " + dir + "/m.obj --layout " +
                           dir + "/m.layout.json --out " + dir + "/out --no-node-opt";
  std::string out;
  ASSERT_EQ(test::run_command(base + " --quad-count 150 --atlas packed", &out), 0) << out;
  const auto patches = uv_patches(read_obj_independently(dir + "/out/quads.obj"));
  EXPECT_EQ(patches.size(), 6u);
  EXPECT_EQ(overlapping_uv_faces(patches, 1000), 0);
  // Without a quad mesh the option has nothing to act on; an unknown layout is refused.
  EXPECT_NE(test::run_command(base + " --atlas packed", &out), 0);
  EXPECT_NE(out.find("--atlas"), std::string::npos) << out;
  EXPECT_NE(test::run_command(base + " --quad-count 150 --atlas tiles", &out), 0);
  EXPECT_NE(out.find("--atlas"), std::string::npos) << out;
}

}  // namespace
}  // namespace qs
