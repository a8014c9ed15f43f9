// The natural cross field of a bare mesh (core/field/natural_field.h): its singularities sit
// where a quad layout wants its irregular nodes (the 8 corners of a cube and of a rounded cube,
// index +1/4 each), a flat disk and a torus get none, and the indices always sum to 4χ.
#include "core/field/natural_field.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <utility>
#include <vector>

#include "core/base/errors.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

int index_sum(const NaturalField& field) {
  int sum = 0;
  for (const auto& s : field.singularities) sum += s.index;
  return sum;
}

// Edge hops from vertex v to the nearest of the layout's node vertices (the cube corners).
int rings_to_nodes(const TriMesh& mesh, const Layout& layout, int v) {
  std::vector<int> sources;
  for (const auto& n : layout.nodes) sources.push_back(n.vertex);
  return test::ring_distances(mesh, sources)[v];
}

// The cube's 8 corners, each with exactly one singularity of index +1 (a quarter turn) within
// \p rings edge rings, and no other singularity.
void expect_cube_corners(const test::MeshAndLayout& ex, const NaturalField& field, int rings) {
  EXPECT_EQ(field.singularities.size(), 8u);
  EXPECT_EQ(index_sum(field), 8);  // 4·χ of the sphere
  std::vector<int> per_corner(ex.layout.nodes.size(), 0);
  for (const auto& s : field.singularities) {
    EXPECT_EQ(s.index, 1) << "vertex " << s.vertex;
    EXPECT_LE(rings_to_nodes(ex.mesh, ex.layout, s.vertex), rings) << "vertex " << s.vertex;
    for (std::size_t n = 0; n < ex.layout.nodes.size(); ++n)
      if (test::ring_distances(ex.mesh, {ex.layout.nodes[n].vertex})[s.vertex] <= rings)
        ++per_corner[n];
  }
  for (std::size_t n = 0; n < per_corner.size(); ++n) EXPECT_EQ(per_corner[n], 1) << "corner " << n;
}

TEST(NaturalField, CubeHasItsSingularitiesAtTheCorners) {
  // The sharp edges are features: the field is parallel to them on every side.
  const auto ex = test::cube_sphere(6, Vec3(1, 1, 1), /*project=*/false);
  const GeometryCache g = build_geometry(ex.mesh);
  const NaturalField field = compute_natural_field(ex.mesh, g);
  EXPECT_GT(field.constraints.count(ConstraintKind::Feature), 0);
  expect_cube_corners(ex, field, 0);
}

TEST(NaturalField, RoundedCubeHasItsSingularitiesNearTheCorners) {
  // Between the cube and the sphere: curved edges with reliable curvature directions (the
  // faces at the corners stay bent enough to count as features).
  auto ex = test::cube_sphere(16, Vec3(1, 1, 1), /*project=*/false);
  for (const auto vh : ex.mesh.vertices()) {
    const Vec3 p = ex.mesh.point(vh);
    Vec3 q = p;
    q.normalize();
    ex.mesh.set_point(vh, 0.3 * p + 0.7 * std::sqrt(3.0) * q);
  }
  const GeometryCache g = build_geometry(ex.mesh);
  const NaturalField field = compute_natural_field(ex.mesh, g);
  EXPECT_GT(field.constraints.count(ConstraintKind::Curvature), 0);
  expect_cube_corners(ex, field, 2);
}

TEST(NaturalField, CubeSphereWithoutConstraintsHasEightQuarterTurnSingularities) {
  // A round sphere: no reliable curvature, no features; the smoothest field by inverse
  // iteration has 8 singularities of +1/4 (the cube-sphere's corners pull them).
  const auto ex = test::cube_sphere(8);
  const GeometryCache g = build_geometry(ex.mesh);
  const NaturalField field = compute_natural_field(ex.mesh, g);
  EXPECT_TRUE(field.constraints.face.empty());
  expect_cube_corners(ex, field, 2);
}

TEST(NaturalField, FlatDiskAndTorusHaveNoSingularity) {
  const auto disk = test::disk_grid(10, 10, 1, 1);
  const GeometryCache gd = build_geometry(disk.mesh);
  const NaturalField fd = compute_natural_field(disk.mesh, gd);
  EXPECT_GT(fd.constraints.count(ConstraintKind::Boundary), 0);
  EXPECT_TRUE(fd.singularities.empty());
  const auto torus = test::torus_grid(48, 24, 1, 1);
  const GeometryCache gt = build_geometry(torus.mesh);
  const NaturalField ft = compute_natural_field(torus.mesh, gt);
  EXPECT_TRUE(ft.singularities.empty());
  ASSERT_EQ(ft.direction.size(), torus.mesh.n_faces());
  for (int f = 0; f < int(torus.mesh.n_faces()); ++f) {
    EXPECT_NEAR(ft.direction[f].norm(), 1.0, 1e-9);
    EXPECT_NEAR(OpenMesh::dot(ft.direction[f], gt.face_normal[f]), 0.0, 1e-9);
  }
}

TEST(NaturalField, OptionsAreChecked) {
  const auto ex = test::cube_sphere(2);
  const GeometryCache g = build_geometry(ex.mesh);
  NaturalFieldOptions o;
  o.constraint_weight = 0.0;
  EXPECT_THROW(compute_natural_field(ex.mesh, g, o), InvalidInputError);
  o = {};
  o.constraint_weight = std::nan("");
  EXPECT_THROW(compute_natural_field(ex.mesh, g, o), InvalidInputError);
  o = {};
  o.curvature_weight = -1.0;
  EXPECT_THROW(compute_natural_field(ex.mesh, g, o), InvalidInputError);
  o = {};
  o.iterations = 0;
  EXPECT_THROW(compute_natural_field(ex.mesh, g, o), InvalidInputError);
}

// cancel_close_pairs on a hand-made list: +1 and −1 one edge apart cancel once the radius
// exceeds that edge, the closest opposite pair goes first, and the index sum stays.
TEST(NaturalField, CloseOppositePairsCancelClosestFirst) {
  const auto ex = test::cube_sphere(8);
  const TriMesh& mesh = ex.mesh;
  const auto vh = OpenMesh::VertexHandle(ex.layout.nodes[0].vertex);
  std::vector<OpenMesh::VertexHandle> ring(mesh.vv_range(vh).begin(), mesh.vv_range(vh).end());
  ASSERT_GE(ring.size(), 3u);
  const double edge = (mesh.point(ring[0]) - mesh.point(vh)).norm();
  const int far = ex.layout.nodes[1].vertex;
  // A +1 at the corner, a −1 next to it, a +1 next to that one (further from the −1 than the
  // corner is, or as far), and a +1 at another corner.
  const int a = vh.idx(), b = ring[0].idx();
  int c = -1;
  double best = 0;
  for (const auto w : mesh.vv_range(ring[0])) {
    const double d = (mesh.point(w) - mesh.point(ring[0])).norm();
    if (w != vh && d > best) best = d, c = w.idx();
  }
  ASSERT_GE(c, 0);
  const std::vector<FieldSingularity> list = {{c, 1}, {a, 1}, {b, -1}, {far, 1}};
  const std::vector<FieldSingularity> none = cancel_close_pairs(mesh, list, 0.5 * edge);
  EXPECT_EQ(none.size(), list.size());
  EXPECT_EQ(cancel_close_pairs(mesh, list, 0.0).size(), list.size());
  const std::vector<FieldSingularity> kept =
      cancel_close_pairs(mesh, list, std::max(best, edge) * 1.01);
  ASSERT_EQ(kept.size(), 2u);
  const double d_ab = (mesh.point(vh) - mesh.point(ring[0])).norm();
  // The −1 went with the nearer of the two +1 next to it (ties: the lower vertex index).
  const int partner = d_ab < best || (d_ab == best && a < c) ? a : c;
  EXPECT_NE(kept[0].vertex, partner);
  EXPECT_EQ(kept[1].vertex, far);
  int sum = 0;
  for (const auto& s : kept) sum += s.index;
  EXPECT_EQ(sum, 2);
  EXPECT_THROW(cancel_close_pairs(mesh, {{int(mesh.n_vertices()), 1}}, 1.0), InvalidInputError);
  EXPECT_THROW(cancel_close_pairs(mesh, list, std::nan("")), InvalidInputError);
}

// Shortest edge-path lengths from vertex \p source (infinity where unreachable).
std::vector<double> edge_distances(const TriMesh& mesh, int source) {
  std::vector<double> dist(mesh.n_vertices(), std::numeric_limits<double>::infinity());
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  dist[source] = 0.0;
  queue.emplace(0.0, source);
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > dist[v]) continue;
    const auto vh = OpenMesh::VertexHandle(v);
    for (const auto w : mesh.vv_range(vh)) {
      const double nd = d + (mesh.point(w) - mesh.point(vh)).norm();
      if (nd < dist[w.idx()]) queue.emplace(dist[w.idx()] = nd, w.idx());
    }
  }
  return dist;
}

// A rounded cube with a bumpy surface: the bumps add dozens of singularity pairs to the
// natural field. At the scale of a tenth of the diagonal most of them cancel, the index sum
// stays 4χ, and no two singularities of opposite index closer than the scale remain.
TEST(NaturalField, BumpySurfaceLosesItsClosePairsAtTheLayoutScale) {
  const auto ex = test::bumpy_rounded_cube();
  const GeometryCache g = build_geometry(ex.mesh);
  const NaturalField field = compute_natural_field(ex.mesh, g);
  ASSERT_GT(field.singularities.size(), 24u) << "the bumps no longer perturb the field";
  Vec3 lo = ex.mesh.point(*ex.mesh.vertices_begin()), hi = lo;
  for (const auto vh : ex.mesh.vertices()) {
    lo.minimize(ex.mesh.point(vh));
    hi.maximize(ex.mesh.point(vh));
  }
  const double radius = 0.1 * (hi - lo).norm();
  NaturalField at_scale = field;
  at_scale.singularities = cancel_close_pairs(ex.mesh, field.singularities, radius);
  EXPECT_LE(3 * at_scale.singularities.size(), field.singularities.size());
  EXPECT_EQ(index_sum(at_scale), 8);
  for (const auto& s : at_scale.singularities) {
    const std::vector<double> dist = edge_distances(ex.mesh, s.vertex);
    for (const auto& t : at_scale.singularities) {
      if (t.index == -s.index) {
        EXPECT_GE(dist[t.vertex], radius) << "vertices " << s.vertex << " and " << t.vertex;
      }
    }
  }
}

}  // namespace
}  // namespace qs
