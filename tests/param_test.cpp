// Seamless parameterization with layout constraints (issue #4).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/extract/tracing.h"
#include "core/field/cross_field.h"
#include "core/layout/validate.h"
#include "core/mesh/geometry.h"
#include "core/param/parameterization.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

struct Solved {
  GeometryCache geometry;
  LayoutTopology topology;
  CrossField field;
  std::unique_ptr<ParamSolver> param;
};

Solved solve_all(const test::MeshAndLayout& in, ParamOptions opt = {}) {
  const auto v = validate_layout(in.mesh, in.layout);
  for (const auto& i : v.issues) ADD_FAILURE() << format_issue(i);
  Solved s;
  s.geometry = build_geometry(in.mesh);
  s.topology = build_topology(in.mesh, in.layout);
  s.field = compute_cross_field(in.mesh, s.geometry, in.layout, s.topology);
  s.param = std::make_unique<ParamSolver>(in.mesh, s.geometry, in.layout, s.topology,
                                          s.field.period_jump, s.field.theta, opt);
  return s;
}

// The corner values of two solves of one system agree to \p tolerance relative to the largest
// coordinate (another ordering changes only the round-off).
void expect_same_corners(const Parameterization& a, const Parameterization& b, double tolerance) {
  ASSERT_EQ(a.corner_uv.size(), b.corner_uv.size());
  double worst = 0, scale = 0;
  for (size_t c = 0; c < a.corner_uv.size(); ++c)
    for (int k = 0; k < 2; ++k) {
      worst = std::max(worst, std::abs(a.corner_uv[c][k] - b.corner_uv[c][k]));
      scale = std::max(scale, std::abs(a.corner_uv[c][k]));
    }
  EXPECT_GT(scale, 0);
  EXPECT_LT(worst, tolerance * scale);
}

// Across every interior edge, the edge vectors of the two faces agree up to the rotation
// −p mod 4 (seamless), and the rotation recovered from the corner values equals −p mod 4.
void expect_seamless(const test::MeshAndLayout& in, const Solved& s) {
  const auto& uv = s.param->result().corner_uv;
  const GeometryCache& g = s.geometry;
  double worst = 0, scale = 0;
  int wrong_rotation = 0;
  for (int e = 0; e < g.n_edges; ++e) {
    const int i = g.edge_face_i[e], j = g.edge_face_j[e];
    if (i < 0 || j < 0) continue;
    const auto [a, b] = g.edge_vertices[e];
    const auto& ia = uv[3 * i + corner_of(g, i, a)];
    const auto& ib = uv[3 * i + corner_of(g, i, b)];
    const auto& ja = uv[3 * j + corner_of(g, j, a)];
    const auto& jb = uv[3 * j + corner_of(g, j, b)];
    const std::array<double, 2> di{ib[0] - ia[0], ib[1] - ia[1]}, dj{jb[0] - ja[0], jb[1] - ja[1]};
    const int r = step_rotation(s.field.period_jump[e], a, b);
    const auto rd = rotate(r, di);
    worst = std::max(worst, std::hypot(dj[0] - rd[0], dj[1] - rd[1]));
    scale = std::max(scale, std::hypot(di[0], di[1]));
    // Recover the rotation from the corner values (libQEx style).
    const double ang = std::atan2(dj[1], dj[0]) - std::atan2(di[1], di[0]);
    const int rec = ((static_cast<int>(std::lround(ang / (M_PI / 2))) % 4) + 4) % 4;
    wrong_rotation += rec != r;
  }
  EXPECT_LT(worst, 1e-8 * scale) << "edge vectors disagree across a seam";
  EXPECT_EQ(wrong_rotation, 0);
  (void)in;
}

// Traces every arc and checks the embedding: all arcs reach their end nodes, no crossings,
// consecutive samples in one face differ in one parameter only, and opposite patch sides
// have equal parametric length.
Extraction expect_valid_embedding(const test::MeshAndLayout& in, const Solved& s) {
  const auto& uv = s.param->result().corner_uv;
  const Extraction ex = extract_layout(in.mesh, s.geometry, in.layout, s.topology,
                                       s.param->labeling(), s.field.period_jump, uv);
  for (const auto& p : ex.problems) ADD_FAILURE() << p;
  EXPECT_TRUE(ex.structurally_equivalent);
  EXPECT_EQ(ex.patch_size.size(), s.topology.patches.size());
  double worst = 0;
  for (size_t a = 0; a < ex.arcs.size(); ++a) {
    const auto& t = ex.arcs[a];
    for (size_t i = 0; i + 1 < t.samples.size(); ++i) {
      const int f = t.samples[i + 1].face;
      const auto p0 = uv_in_face(in.mesh, s.geometry, uv, t.samples[i], f);
      const auto p1 = uv_in_face(in.mesh, s.geometry, uv, t.samples[i + 1], f);
      const double du = std::abs(p1[0] - p0[0]), dv = std::abs(p1[1] - p0[1]);
      const double moving = std::max(du, dv), fixed = std::min(du, dv);
      if (moving > 1e-12) worst = std::max(worst, fixed / moving);
    }
  }
  EXPECT_LT(worst, 1e-6) << "iso-line violation";
  for (const auto& P : s.topology.patches) {
    if (P.darts.size() != 4) continue;
    const double l0 = ex.arcs[P.darts[0] >> 1].param_length,
                 l2 = ex.arcs[P.darts[2] >> 1].param_length;
    const double l1 = ex.arcs[P.darts[1] >> 1].param_length,
                 l3 = ex.arcs[P.darts[3] >> 1].param_length;
    EXPECT_NEAR(l0, l2, 1e-6 * std::max(l0, l2));
    EXPECT_NEAR(l1, l3, 1e-6 * std::max(l1, l3));
  }
  return ex;
}

TEST(Parameterization, CubeOnSphereIsSeamlessAndFoldFree) {
  const auto in = test::cube_sphere(8);
  const Solved s = solve_all(in);
  const auto& r = s.param->result();
  expect_seamless(in, s);
  EXPECT_EQ(r.foldovers, 0);
  EXPECT_GT(r.energy, 0);
  EXPECT_EQ(s.param->labeling().geometric_mismatches, 0);
  EXPECT_GT(r.redundant, 0) << "node rows implied by the others must be detected";
  expect_valid_embedding(in, s);
}

TEST(Parameterization, TorusGridIsSeamless) {
  const auto in = test::torus_grid(32, 16, 4, 2);
  const Solved s = solve_all(in);
  expect_seamless(in, s);
  EXPECT_EQ(s.param->result().foldovers, 0);
  expect_valid_embedding(in, s);
}

TEST(Parameterization, FlatPolycubeIsIsometric) {
  const auto in = test::genus2_polycube(3);
  const Solved s = solve_all(in);
  expect_seamless(in, s);
  const auto& r = s.param->result();
  EXPECT_EQ(r.foldovers, 0);
  double area = 0;
  for (double a : s.geometry.face_area) area += a;
  EXPECT_LT(r.energy, 1e-10 * area);
  expect_valid_embedding(in, s);
}

TEST(Parameterization, FlatDiskGridIsIsometric) {
  const auto in = test::disk_grid(12, 8, 3, 2);
  const Solved s = solve_all(in);
  const auto& r = s.param->result();
  EXPECT_EQ(r.foldovers, 0);
  EXPECT_LT(r.energy, 1e-10 * 96);
  expect_valid_embedding(in, s);
}

// ParamOptions::wedge_ordering: the linear solver's analysis uses the wedge-graph ordering
// (one group per wedge, holding only that wedge's unknowns), and the solution is the default
// ordering's up to round-off (the reduced system has a unique solution).
TEST(Parameterization, WedgeOrderingIsUsedAndGivesTheSameSolution) {
  const auto in = test::cube_sphere(8);
  ParamOptions wedge;
  wedge.wedge_ordering = true;
  const Solved a = solve_all(in), b = solve_all(in, wedge);
  EXPECT_EQ(a.param->linear_solver().stats().hinted_analyses, 0);
  EXPECT_EQ(b.param->linear_solver().stats().hinted_analyses, 1);
  const Reduction& red = b.param->reduction();
  const int wedges = b.param->cut_graph().wedges;
  const int free = static_cast<int>(red.Z.cols());
  const std::vector<int> group = parameterization_groups(wedges, red.free_index, free);
  ASSERT_EQ(group.size(), static_cast<size_t>(free));
  std::vector<int> group_wedge(free, -2), group_size(free, 0);
  for (int i = 0; i < static_cast<int>(red.free_index.size()); ++i) {
    const int k = red.free_index[i];
    if (k < 0) continue;
    const int w = i < 2 * wedges ? i / 2 : -1;  // -1: a seam translation, alone in its group
    const int g = group[k];
    ASSERT_GE(g, 0);
    ASSERT_LT(g, free);
    if (group_wedge[g] == -2) group_wedge[g] = w;
    EXPECT_EQ(group_wedge[g], w) << "unknown " << k;
    EXPECT_LE(++group_size[g], w < 0 ? 1 : 2);
  }
  expect_same_corners(a.param->result(), b.param->result(), 1e-9);
  EXPECT_NEAR(a.param->result().energy, b.param->result().energy, 1e-9 * a.param->result().energy);
}

// ParamOptions::vertex_order: the analysis takes the vertex order expanded to the unknowns
// (a hinted analysis), and the solution is CHOLMOD's ordering's up to round-off; an order of
// another size is not used.
TEST(Parameterization, VertexOrderIsUsedAndGivesTheSameSolution) {
  for (const auto& in : {test::cube_sphere(8), test::torus_grid(32, 16, 4, 2)}) {
    const GeometryCache g = build_geometry(in.mesh);
    const std::vector<int> order = vertex_nested_dissection(g);
    ASSERT_EQ(order.size(), static_cast<size_t>(g.n_vertices));
    std::vector<int> sorted = order;
    std::sort(sorted.begin(), sorted.end());
    for (int k = 0; k < g.n_vertices; ++k) ASSERT_EQ(sorted[k], k) << "not a permutation";
    ParamOptions ordered, wrong;
    ordered.vertex_order = std::make_shared<const std::vector<int>>(order);
    wrong.vertex_order = std::make_shared<const std::vector<int>>(order.begin(), order.end() - 1);
    const Solved a = solve_all(in), b = solve_all(in, ordered), c = solve_all(in, wrong);
    EXPECT_EQ(a.param->linear_solver().stats().hinted_analyses, 0);
    EXPECT_EQ(b.param->linear_solver().stats().hinted_analyses, 1);
    EXPECT_EQ(c.param->linear_solver().stats().hinted_analyses, 0);
    EXPECT_EQ(c.param->result().corner_uv, a.param->result().corner_uv);
    expect_same_corners(a.param->result(), b.param->result(), 1e-9);
    EXPECT_NEAR(a.param->result().energy, b.param->result().energy,
                1e-9 * a.param->result().energy);
  }
}

// A geometry cache without the kept hat-function gradients (not made by build_geometry) is
// refused with a message, not read out of bounds.
TEST(Parameterization, GeometryWithoutFaceGradientsIsRefused) {
  const auto in = test::cube_sphere(4);
  const Solved s = solve_all(in);
  GeometryCache broken = s.geometry;
  broken.face_gradient.clear();
  try {
    ParamSolver solver(in.mesh, broken, in.layout, s.topology, s.field.period_jump, s.field.theta);
    ADD_FAILURE() << "no error";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("face gradients"), std::string::npos) << e.what();
  }
}

// ParamOptions::second_thread (labels beside the cut graph, the analysis beside the assembly)
// changes nothing in the results: bit-identical corner values, energy and labels, with and
// without the sizing field (its solve is part of the assembly the analysis overlaps).
TEST(Parameterization, SecondThreadGivesIdenticalResults) {
  const auto in = test::cube_sphere(8);
  for (const bool sizing : {false, true}) {
    ParamOptions one, two;
    one.second_thread = false;
    two.second_thread = true;
    one.sizing.enabled = two.sizing.enabled = sizing;
    const Solved a = solve_all(in, one), b = solve_all(in, two);
    EXPECT_EQ(a.param->result().corner_uv, b.param->result().corner_uv) << "sizing " << sizing;
    EXPECT_EQ(a.param->result().energy, b.param->result().energy);
    EXPECT_EQ(a.param->labeling().chart_face, b.param->labeling().chart_face);
    EXPECT_EQ(a.param->cut_graph().corner_wedge, b.param->cut_graph().corner_wedge);
    EXPECT_EQ(b.param->linear_solver().stats().analyses, 1);
    EXPECT_EQ(b.param->linear_solver().stats().factorizations, 1);
    EXPECT_GT(b.param->linear_solver().stats().analyze_s, 0);
  }
}

// On a mesh large enough for the set-up's threads (H's wedge pattern beside the elimination
// from 8192 wedges, A's pattern in two halves from 16384 unknowns): the same solve, bitwise.
TEST(Parameterization, SecondThreadGivesIdenticalResultsOnALargeMesh) {
  const auto in = test::cube_sphere(40);
  ParamOptions one, two;
  one.second_thread = false;
  two.second_thread = true;
  const Solved a = solve_all(in, one), b = solve_all(in, two);
  ASSERT_GE(b.param->result().wedges, 8192) << "the case must reach the threaded set-up";
  ASSERT_GE(b.param->result().unknowns, 16384) << "the case must reach the threaded set-up";
  EXPECT_EQ(a.param->result().unknowns, b.param->result().unknowns);
  EXPECT_EQ(a.param->result().corner_uv, b.param->result().corner_uv);
  EXPECT_EQ(a.param->result().energy, b.param->result().energy);
  EXPECT_EQ(b.param->result().foldovers, 0);
}

// ParamSolver(…, solve_now = false): no result until the first solve, which then equals the
// constructor's own solve; the analysis started in the constructor is the only one, and a
// solver destroyed before any solve waits for it (run under TSan in CI).
TEST(Parameterization, SecondThreadDeferredFirstSolve) {
  const auto in = test::cube_sphere(8);
  const Solved a = solve_all(in);
  for (const bool second_thread : {false, true}) {
    ParamOptions opt;
    opt.second_thread = second_thread;
    {
      ParamSolver unused(in.mesh, a.geometry, in.layout, a.topology, a.field.period_jump,
                         a.field.theta, opt, nullptr, false);
    }
    ParamSolver deferred(in.mesh, a.geometry, in.layout, a.topology, a.field.period_jump,
                         a.field.theta, opt, nullptr, false);
    EXPECT_TRUE(deferred.result().corner_uv.empty());
    EXPECT_EQ(deferred.linear_solver().stats().factorizations, 0);
    const Parameterization& r = deferred.solve(in.mesh, a.geometry, a.field.theta);
    EXPECT_EQ(r.corner_uv, a.param->result().corner_uv) << "second thread " << second_thread;
    EXPECT_EQ(r.energy, a.param->result().energy);
    EXPECT_EQ(deferred.linear_solver().stats().analyses, 1);
    EXPECT_EQ(deferred.linear_solver().stats().factorizations, 1);
  }
}

// TraceOptions::second_thread_arcs: tracing half of the arcs on a second thread gives the same
// extraction as one thread (every sample, the problems in arc order, the equivalence).
TEST(Parameterization, SecondThreadTracesTheSameArcs) {
  for (const auto& in : {test::torus_grid(32, 16, 4, 2), test::cube_sphere(8)}) {
    const Solved s = solve_all(in);
    TraceOptions one, two;
    one.second_thread_arcs = 0;
    two.second_thread_arcs = 1;  // any layout
    const auto& uv = s.param->result().corner_uv;
    const Extraction a = extract_layout(in.mesh, s.geometry, in.layout, s.topology,
                                        s.param->labeling(), s.field.period_jump, uv, one);
    const Extraction b = extract_layout(in.mesh, s.geometry, in.layout, s.topology,
                                        s.param->labeling(), s.field.period_jump, uv, two);
    ASSERT_EQ(a.arcs.size(), b.arcs.size());
    ASSERT_GT(a.arcs.size(), 1u);
    for (size_t k = 0; k < a.arcs.size(); ++k) {
      EXPECT_EQ(a.arcs[k].ok, b.arcs[k].ok) << "arc " << k;
      EXPECT_EQ(a.arcs[k].polyline, b.arcs[k].polyline) << "arc " << k;
      EXPECT_EQ(a.arcs[k].uv, b.arcs[k].uv) << "arc " << k;
      EXPECT_EQ(a.arcs[k].param_length, b.arcs[k].param_length) << "arc " << k;
    }
    EXPECT_EQ(a.problems, b.problems);
    EXPECT_EQ(a.crossings, b.crossings);
    EXPECT_TRUE(a.structurally_equivalent);
    EXPECT_EQ(a.structurally_equivalent, b.structurally_equivalent);
  }
}

}  // namespace
}  // namespace qs
