// Arcs whose iso-lines run exactly along mesh edges (issue #44 item 3): the exact 4×4 grid
// layout of a torus whose arcs follow the mesh's grid lines (assets/repro/torus_4x4.*). Every
// arc of such a layout is an iso-line through mesh vertices and along mesh edges, so the tracer
// meets vertices and edges head-on at every step, and round-off decides on which side of them
// the traced line passes. The extraction must be structurally equivalent and the quad mesh
// complete whatever the round-off: the tests move every vertex by a tiny deterministic offset
// (up to 1e-9 and 1e-7 of the bounding-box diagonal, as another CPU's or solver's round-off would
// perturb the parameterization).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

#include "core/extract/quads.h"
#include "core/layout/layout_io.h"
#include "core/pipeline/pipeline.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

// Moves every vertex by an offset of at most \p fraction of the bounding-box diagonal per
// coordinate, from a hash of (vertex index, coordinate, seed): the same on every machine.
void perturb(TriMesh& mesh, double fraction, uint32_t seed) {
  Vec3 lo(1e300, 1e300, 1e300), hi(-1e300, -1e300, -1e300);
  for (auto v : mesh.vertices()) {
    lo.minimize(mesh.point(v));
    hi.maximize(mesh.point(v));
  }
  const double scale = fraction * (hi - lo).norm();
  for (auto v : mesh.vertices()) {
    Vec3 p = mesh.point(v);
    for (int c = 0; c < 3; ++c) {
      uint32_t h = static_cast<uint32_t>(v.idx()) * 2654435761u ^ (c + 1) * 40503u ^ seed * 97u;
      h ^= h >> 16;
      h *= 2246822519u;
      h ^= h >> 13;
      h *= 3266489917u;
      h ^= h >> 16;
      p[c] += scale * (2.0 * (h / 4294967295.0) - 1.0);
    }
    mesh.set_point(v, p);
  }
}

// optimize --no-node-opt --quad-size 0.05 on the torus grid, with the mesh perturbed.
void expect_grid_embeds(double fraction, uint32_t seed) {
  char what[64];
  std::snprintf(what, sizeof what, "perturbation %g, seed %u", fraction, seed);
  SCOPED_TRACE(what);
  const std::string dir = test::assets_dir() + "/repro";
  TriMesh mesh = test::load_mesh(dir + "/torus_4x4.obj");
  if (fraction > 0) perturb(mesh, fraction, seed);
  const Layout layout = load_layout(dir + "/torus_4x4.layout.json", mesh);
  Pipeline pipeline(mesh, layout);
  const Parameterization& param = pipeline.compute_parameterization();
  EXPECT_EQ(param.foldovers, 0);
  const Extraction& ex = pipeline.extract();
  for (const auto& p : ex.problems) ADD_FAILURE() << p;
  EXPECT_TRUE(ex.structurally_equivalent);
  EXPECT_EQ(ex.crossings, 0);
  QuadMeshOptions qo;
  qo.quad_size = 0.05;
  const QuadMesh quads = build_quad_mesh(pipeline, ex, qo);
  for (const auto& w : quads.warnings) ADD_FAILURE() << w;
  EXPECT_EQ(quads.gridded_patches(), 16);
  // A closed grid of quads on a torus: as many vertices as quads.
  EXPECT_EQ(quads.vertices.size(), quads.quads.size());
}

TEST(TracingGrid, ExactTorusGridEmbeds) {
  expect_grid_embeds(0, 0);
}

TEST(TracingGrid, ExactTorusGridEmbedsUnderRoundOff) {
  for (uint32_t seed = 1; seed <= 8; ++seed) {
    for (double f : {1e-12, 1e-10, 3e-10, 1e-9, 1e-8, 1e-7}) expect_grid_embeds(f, seed);
  }
}

}  // namespace
}  // namespace qs
