// The natural cross field of a bare mesh (core/field/natural_field.h): its singularities sit
// where a quad layout wants its irregular nodes (the 8 corners of a cube and of a rounded cube,
// index +1/4 each), a flat disk and a torus get none, and the indices always sum to 4χ.
#include "core/field/natural_field.h"

#include <gtest/gtest.h>

#include <cmath>

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

}  // namespace
}  // namespace qs
