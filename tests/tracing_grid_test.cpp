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
#include "core/nodeopt/optimizer.h"
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

// The extraction of \p pipeline's parameterization and its quad mesh at quad size 0.05 (the
// repro's `--quad-size 0.05`): structurally equivalent, every patch gridded.
void expect_complete_quad_mesh(Pipeline& pipeline) {
  const Parameterization& param = pipeline.parameterization() ? *pipeline.parameterization()
                                                              : pipeline.compute_parameterization();
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

struct TorusInput {
  TriMesh mesh;
  Layout layout;
};

// The torus grid repro with the mesh perturbed by \p fraction (0: exact).
TorusInput torus_input(double fraction, uint32_t seed) {
  const std::string dir = test::assets_dir() + "/repro";
  TorusInput in;
  in.mesh = test::load_mesh(dir + "/torus_4x4.obj");
  if (fraction > 0) perturb(in.mesh, fraction, seed);
  in.layout = load_layout(dir + "/torus_4x4.layout.json", in.mesh);
  return in;
}

std::string trace_label(double fraction, uint32_t seed) {
  char what[64];
  std::snprintf(what, sizeof what, "perturbation %g, seed %u", fraction, seed);
  return what;
}

// optimize --no-node-opt --quad-size 0.05 on the torus grid, with the mesh perturbed.
void expect_grid_embeds(double fraction, uint32_t seed) {
  SCOPED_TRACE(trace_label(fraction, seed));
  const TorusInput in = torus_input(fraction, seed);
  Pipeline pipeline(in.mesh, in.layout);
  expect_complete_quad_mesh(pipeline);
}

TEST(TracingGrid, ExactTorusGridEmbeds) {
  expect_grid_embeds(0, 0);
}

TEST(TracingGrid, ExactTorusGridEmbedsUnderRoundOff) {
  for (uint32_t seed = 1; seed <= 8; ++seed) {
    for (double f : {1e-12, 1e-10, 3e-10, 1e-9, 1e-8, 1e-7}) expect_grid_embeds(f, seed);
  }
}

// optimize --quad-size 0.05 (with the node optimization, as in the issue) on the perturbed
// torus grid: the exact grid is a stationary layout (E changes by round-off only), the descent
// never raises E, and the final state embeds with every patch of the quad mesh.
TEST(TracingGrid, NodeOptimizedTorusGridEmbedsUnderRoundOff) {
  for (uint32_t seed = 1; seed <= 4; ++seed) {
    SCOPED_TRACE(trace_label(1e-10, seed));
    const TorusInput in = torus_input(1e-10, seed);
    const NodeOptResult r = optimize_nodes(in.mesh, in.layout, PipelineOptions{}, NodeOptOptions{});
    EXPECT_LE(r.E_final, r.E_init);
    EXPECT_EQ(r.foldovers_final, 0);
    ASSERT_TRUE(r.pipeline);
    expect_complete_quad_mesh(*r.pipeline);
    std::printf("[stat] torus 4x4, seed %u: E %.10g -> %.10g in %d steps (%d accepted)\n", seed,
                r.E_init, r.E_final, r.steps, r.accepted);
  }
}

}  // namespace
}  // namespace qs
