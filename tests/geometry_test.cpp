// The geometry cache under vertex moves: κ continued across updates keeps the parallel
// transport around every vertex (docs/design.md, "Continuing κ").
#include "core/mesh/geometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "tests/fixtures.h"

namespace qs {
namespace {

// Σ σ·κ over the edges of interior vertex v (σ = +1 where v is the edge's second vertex: the
// counter-clockwise loop around v crosses it from face i to face j) minus the angle defect:
// parallel transport around v turns a direction by the defect, so this is a multiple of 2π.
double transport_residual(const GeometryCache& g, int v) {
  double h = 0;
  for (int e = 0; e < g.n_edges; ++e) {
    if (g.edge_face_i[e] < 0 || g.edge_face_j[e] < 0) continue;
    if (g.edge_vertices[e][1] == v) h += g.kappa[e];
    if (g.edge_vertices[e][0] == v) h -= g.kappa[e];
  }
  return h - g.angle_defect[v];
}

TEST(Geometry, TransportAroundAVertexIsTheAngleDefect) {
  const auto cs = test::cube_sphere(6, Vec3(1.6, 1.0, 0.7));
  GeometryCache g = build_geometry(cs.mesh);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  std::vector<double> offsets(g.n_faces);
  for (double& o : offsets) o = angle(rng);
  set_frame_offsets(cs.mesh, g, offsets);
  for (int v = 0; v < g.n_vertices; ++v) {
    const double turns = transport_residual(g, v) / (2 * M_PI);
    ASSERT_NEAR(turns, std::round(turns), 1e-9) << "vertex " << v;
  }
}

// Vertices jump far across their 1-rings in single updates (as node relocation trials do when
// the optimizer re-solves its Pipeline in place for trial after trial): the frames of a face
// pair can turn by more than π against each other in one update, where κ_old + wrap(κ − κ_old)
// takes the wrong branch. update_geometry keeps every vertex's transport residual, and κ stays
// the freshly computed κ up to multiples of 2π.
TEST(Geometry, ContinuedKappaKeepsTheTransportAroundEveryVertex) {
  const auto cs = test::cube_sphere(6, Vec3(1.6, 1.0, 0.7));
  TriMesh mesh = cs.mesh;
  const TriMesh original = cs.mesh;
  GeometryCache g = build_geometry(mesh);
  std::vector<double> residual(g.n_vertices);
  for (int v = 0; v < g.n_vertices; ++v) residual[v] = transport_residual(g, v);
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(mesh.n_vertices()) - 1);
  std::uniform_real_distribution<double> reach(0.5, 0.9);
  int plain_wrong = 0;  // edges where the plain continuation took the wrong branch
  for (int round = 0; round < 60; ++round) {
    // A few vertices, each to a point towards a random neighbour (original positions).
    for (int k = 0; k < 3; ++k) {
      const auto v = mesh.vertex_handle(pick(rng));
      std::vector<OpenMesh::VertexHandle> ring(mesh.vv_range(v).begin(), mesh.vv_range(v).end());
      const auto w = ring[std::uniform_int_distribution<size_t>(0, ring.size() - 1)(rng)];
      mesh.set_point(v, original.point(v) + reach(rng) * (original.point(w) - original.point(v)));
    }
    const std::vector<double> before = g.kappa;
    update_geometry(mesh, g);
    const GeometryCache fresh = build_geometry(mesh);
    for (int e = 0; e < g.n_edges; ++e) {
      const double turns = (g.kappa[e] - fresh.kappa[e]) / (2 * M_PI);
      ASSERT_NEAR(turns, std::round(turns), 1e-9) << "round " << round << " edge " << e;
      const double plain = before[e] + std::remainder(fresh.kappa[e] - before[e], 2 * M_PI);
      plain_wrong += std::abs(plain - g.kappa[e]) > M_PI;
    }
    for (int v = 0; v < g.n_vertices; ++v)
      ASSERT_NEAR(transport_residual(g, v), residual[v], 1e-8)
          << "round " << round << " vertex " << v;
  }
  std::printf("[stat] updates where κ_old + wrap(κ − κ_old) took the wrong branch: %d edges\n",
              plain_wrong);
  EXPECT_GT(plain_wrong, 0) << "the moves never needed the correction";
}

}  // namespace
}  // namespace qs
