// Reuse of work between node-optimization trials (issue #5): a Pipeline continued from the
// previous one (Pipeline(mesh, layout, previous)) after nodes switched vertices AND vertices
// were relocated must give a fresh Pipeline's field at that geometry (the constraint set is
// collected again from the relocated geometry's curvature).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>

#include "core/field/curvature.h"
#include "core/import/quad_import.h"
#include "core/layout/layout_io.h"
#include "core/layout/routing.h"
#include "core/mesh/mesh_io.h"
#include "core/nodeopt/optimizer.h"
#include "core/nodeopt/relocation.h"
#include "core/param/reduced_assembly.h"
#include "core/pipeline/pipeline.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

using Example = test::MeshAndLayout;
using test::ellipsoid_example;

// Moves every unpinned node one ring away (re-routed), as a node optimization trial does.
Layout moved_layout(const TriMesh& mesh, Layout layout, unsigned seed) {
  std::mt19937 rng(seed);
  for (int n = 0; n < static_cast<int>(layout.nodes.size()); ++n) {
    if (layout.nodes[n].pinned) continue;
    auto cand = test::ring_vertices(mesh, layout.nodes[n].vertex, 1);
    std::shuffle(cand.begin(), cand.end(), rng);
    for (int w : cand) {
      if (forbidden_relocation_vertices(mesh, layout, n)[w]) continue;
      if (move_node_and_reroute(mesh, layout, n, w)) break;
    }
  }
  return layout;
}

// Relocates the vertices within one ring of every node: each moves `fraction` of the way to a
// random neighbour (as the descent's continuous relocation moves node vertices in the surface).
TriMesh relocated(const TriMesh& mesh, const Layout& layout, double fraction, unsigned seed) {
  TriMesh out = mesh;
  std::mt19937 rng(seed);
  for (const auto& node : layout.nodes) {
    for (int v : test::ring_vertices(mesh, node.vertex, 1)) {
      const auto vh = mesh.vertex_handle(v);
      std::vector<int> nb;
      for (auto w : mesh.vv_range(vh)) nb.push_back(w.idx());
      const int w = nb[std::uniform_int_distribution<int>(0, static_cast<int>(nb.size()) - 1)(rng)];
      const Vec3 p = mesh.point(vh);
      out.set_point(vh, p + fraction * (mesh.point(mesh.vertex_handle(w)) - p));
    }
  }
  return out;
}

double energy(const Pipeline& p, const PipelineOptions& options) {
  return unweighted_energy(p.mesh(), p.geometry(), p.field()->theta, *p.parameterization(),
                           options.param);
}

bool same_constraint_faces(const FieldConstraints& a, const FieldConstraints& b) {
  return a.face == b.face && a.kind == b.kind;
}

// Nodes moved one ring and the vertices around them relocated: the continued Pipeline's field
// is the fresh Pipeline's at the relocated geometry (same constraint faces and directions, same
// singularities, θ equal modulo quarter turns to solver tolerance, same E and fold-overs),
// whether the relocation changed the constraint faces or only their directions.
// (Whole constraint clusters: with split ones the continued field keeps the layout field's
// rotation the first construction chose, CrossFieldSolver::update_layout.)
void check_continued_matches_fresh(const Example& ex) {
  PipelineOptions options;
  options.field.max_cluster_faces = 0;
  Pipeline first(ex.mesh, ex.layout, options);
  first.compute_field();
  first.compute_parameterization();
  int changed_sets = 0, cases = 0;
  for (double fraction : {0.05, 0.45})
    for (unsigned seed : {1u, 2u}) {
      ++cases;
      const Layout moved = moved_layout(ex.mesh, ex.layout, seed);
      const TriMesh mesh = relocated(ex.mesh, ex.layout, fraction, seed);
      Pipeline fresh(mesh, moved, options);
      fresh.compute_field();
      fresh.compute_parameterization();
      Pipeline continued(mesh, moved, first);
      continued.compute_field();
      continued.compute_parameterization();
      const FieldConstraints& cf = fresh.field()->constraints;
      const FieldConstraints& cc = continued.field()->constraints;
      changed_sets += !same_constraint_faces(cf, first.field()->constraints);
      ASSERT_TRUE(same_constraint_faces(cf, cc)) << "fraction " << fraction << " seed " << seed;
      double worst_dir = 0;
      for (size_t k = 0; k < cf.direction.size(); ++k)
        worst_dir = std::max(worst_dir, (cf.direction[k] - cc.direction[k]).norm());
      EXPECT_LT(worst_dir, 1e-12);
      const test::FieldGap gap = test::field_gap(fresh, continued);
      ASSERT_TRUE(gap.same_singularities) << "fraction " << fraction << " seed " << seed;
      const double worst = gap.max_theta;
      const double Ef = energy(fresh, options), Ec = energy(continued, options);
      std::printf(
          "[stat] fraction %.2f seed %u: constraint faces %zu (first %zu, %s), max |dθ| %.3g, "
          "E %.9g vs fresh %.9g, fold-overs %d vs %d\n",
          fraction, seed, cf.face.size(), first.field()->constraints.face.size(),
          same_constraint_faces(cf, first.field()->constraints) ? "same" : "changed", worst, Ec, Ef,
          continued.parameterization()->foldovers, fresh.parameterization()->foldovers);
      EXPECT_LT(worst, 1e-7) << "fraction " << fraction << " seed " << seed;
      EXPECT_NEAR(Ec, Ef, 1e-7 * Ef) << "fraction " << fraction << " seed " << seed;
      EXPECT_EQ(continued.parameterization()->foldovers, fresh.parameterization()->foldovers);
    }
  // The large relocations change the constraint faces (the set-up-again path is exercised).
  EXPECT_GT(changed_sets, 0) << "no case changed the constraint set: the test is too weak";
  EXPECT_EQ(cases, 4);
}

TEST(ReuseField, ContinuedFieldMatchesFreshAtRelocatedGeometry) {
  check_continued_matches_fresh(ellipsoid_example());
}

// An anisotropic cube sphere: many curvature constraints, whose faces and directions move with
// the relocated vertices.
TEST(ReuseField, ContinuedFieldMatchesFreshWithCurvatureConstraints) {
  const auto cs = test::cube_sphere(8, Vec3(2.0, 1.0, 0.6));
  Example ex{cs.mesh, cs.layout};
  {
    Pipeline p(ex.mesh, ex.layout);
    ASSERT_GT(p.compute_field().constraints.count(ConstraintKind::Curvature), 20);
  }
  check_continued_matches_fresh(ex);
}

// update_curvature after a few vertices moved gives exactly compute_curvature at the new
// positions (the incremental sums follow the same order), and the reliable set changes.
TEST(ReuseField, IncrementalCurvatureIsBitIdentical) {
  const auto cs = test::cube_sphere(10, Vec3(2.0, 1.0, 0.6));
  const GeometryCache g0 = build_geometry(cs.mesh);
  CurvatureCache cache;
  const Curvature c0 = compute_curvature(cs.mesh, g0, {}, &cache);
  ASSERT_GT(c0.reliable_faces, 0);
  TriMesh mesh = cs.mesh;
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(mesh.n_vertices()) - 1);
  int changed_faces = 0;
  for (int round = 0; round < 3; ++round) {
    for (int k = 0; k < 12; ++k) {
      const auto v = mesh.vertex_handle(pick(rng));
      const auto w = *mesh.vv_range(v).begin();
      mesh.set_point(
          v, mesh.point(v) + 0.4 * (mesh.point(w) - mesh.point(v)) + 0.05 * Vec3(1.0, -0.5, 0.25));
    }
    const GeometryCache g = build_geometry(mesh);
    const Curvature fast = update_curvature(mesh, g, {}, cache);
    const Curvature full = compute_curvature(mesh, g);
    ASSERT_EQ(fast.k_max, full.k_max) << "round " << round;
    ASSERT_EQ(fast.k_min, full.k_min);
    for (size_t f = 0; f < full.dir_max.size(); ++f) ASSERT_EQ(fast.dir_max[f], full.dir_max[f]);
    ASSERT_EQ(fast.reliable, full.reliable);
    EXPECT_EQ(fast.reliable_faces, full.reliable_faces);
    for (size_t f = 0; f < full.k_max.size(); ++f) changed_faces += full.k_max[f] != c0.k_max[f];
  }
  EXPECT_GT(changed_faces, 0) << "the moves did not change the curvature";
  // Unchanged positions: the cached result.
  const Curvature same = update_curvature(mesh, build_geometry(mesh), {}, cache);
  EXPECT_EQ(same.k_max, compute_curvature(mesh, build_geometry(mesh)).k_max);
}

// update_geometry after a few vertices moved (the incremental path) equals the full
// recomputation with κ continued, bit for bit (κ to round-off), over several rounds.
TEST(ReuseField, IncrementalGeometryIsBitIdentical) {
  const auto cs = test::cube_sphere(10, Vec3(2.0, 1.0, 0.6));
  TriMesh mesh = cs.mesh;
  GeometryCache g = build_geometry(mesh);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  std::vector<double> offsets(g.n_faces);
  for (double& o : offsets) o = angle(rng);
  set_frame_offsets(mesh, g, offsets);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(mesh.n_vertices()) - 1);
  int changed_kappa = 0;
  for (int round = 0; round < 4; ++round) {
    for (int k = 0; k < 10; ++k) {
      const auto v = mesh.vertex_handle(pick(rng));
      const auto w = *mesh.vv_range(v).begin();
      mesh.set_point(v, mesh.point(v) + 0.45 * (mesh.point(w) - mesh.point(v)));
    }
    GeometryCache full = g;
    full.positions.clear();  // forces the full recomputation (κ continued)
    update_geometry(mesh, full);
    const std::vector<double> kappa_before = g.kappa;
    update_geometry(mesh, g);
    // κ of an edge away from the moves keeps its value; the full pass re-continues it, which
    // can change its last bits (old + wrap(k − old) is not exactly old).
    for (size_t e = 0; e < g.kappa.size(); ++e)
      ASSERT_NEAR(g.kappa[e], full.kappa[e], 1e-13) << "round " << round << " edge " << e;
    ASSERT_EQ(g.face_area, full.face_area);
    ASSERT_EQ(g.corner_angle, full.corner_angle);
    ASSERT_EQ(g.face_gradient, full.face_gradient);
    ASSERT_EQ(g.angle_defect, full.angle_defect);
    ASSERT_EQ(g.edge_length, full.edge_length);
    ASSERT_EQ(g.mean_edge_length, full.mean_edge_length);
    ASSERT_EQ(g.bbox_diagonal, full.bbox_diagonal);
    for (int f = 0; f < g.n_faces; ++f) {
      ASSERT_EQ(g.face_normal[f], full.face_normal[f]) << "face " << f;
      ASSERT_EQ(g.face_frame[f], full.face_frame[f]) << "face " << f;
    }
    for (size_t e = 0; e < g.kappa.size(); ++e) changed_kappa += g.kappa[e] != kappa_before[e];
    // The kept hat-function gradients are those of the moved corners in the current frames:
    // ∇φ_k · (c_j − c_0) = δ_kj − δ_k0, and their area is the face's.
    for (int f = 0; f < g.n_faces; ++f) {
      const auto c = face_corners_2d(mesh, g, f);
      const auto& grad = g.face_gradient[f];
      for (int k = 0; k < 3; ++k)
        for (int j = 1; j < 3; ++j) {
          const double dot =
              grad[2 * k] * (c[j][0] - c[0][0]) + grad[2 * k + 1] * (c[j][1] - c[0][1]);
          ASSERT_NEAR(dot, (k == j) - (k == 0), 1e-9) << "face " << f << " corner " << k;
        }
      ASSERT_NEAR(grad[6], g.face_area[f], 1e-12 * g.face_area[f]) << "face " << f;
    }
  }
  EXPECT_GT(changed_kappa, 0) << "the moves did not change κ";
  // A fresh build at the final positions has the same geometry (κ up to multiples of 2π).
  GeometryCache fresh = build_geometry(mesh);
  set_frame_offsets(mesh, fresh, offsets);
  for (int e = 0; e < g.n_edges; ++e)
    EXPECT_NEAR(std::remainder(g.kappa[e] - fresh.kappa[e], 2 * M_PI), 0.0, 1e-12) << "edge " << e;
}

// Largest |Δu|, |Δv| over all corners, relative to the parameter range of \p a.
double corner_gap(const std::vector<std::array<double, 2>>& a,
                  const std::vector<std::array<double, 2>>& b) {
  EXPECT_EQ(a.size(), b.size());
  double range = 0, gap = 0;
  for (size_t c = 0; c < a.size() && c < b.size(); ++c)
    for (int i = 0; i < 2; ++i) {
      range = std::max(range, std::abs(a[c][i]));
      gap = std::max(gap, std::abs(a[c][i] - b[c][i]));
    }
  return gap / std::max(range, 1e-300);
}

// A parameterization solver set up for one field (solve_now false) is kept for another only
// when the constraint rows are the same: same period jumps, same feature-edge directions, arc
// labels equal up to a half turn. Adopted, it solves exactly as a solver built for that field.
TEST(ReuseParam, AdoptsASolverSetUpForAnotherFieldOnlyWithTheSameRows) {
  auto cs = test::cube_sphere(8, Vec3(2.0, 1.0, 0.6));
  const TriMesh& mesh = cs.mesh;
  const GeometryCache g = build_geometry(mesh);
  Layout layout = cs.layout;
  // A feature edge that is not an arc edge, away from the nodes (their chart faces).
  const std::vector<char> arc_edge = arc_edge_mask(mesh, layout);
  std::vector<char> near_node(g.n_vertices, 0);
  for (const auto& n : layout.nodes)
    for (int v : test::ring_vertices(mesh, n.vertex, 2)) near_node[v] = 1;
  int feature_face = -1;
  for (auto e : mesh.edges()) {
    const auto h = mesh.halfedge_handle(e, 0);
    const int a = mesh.from_vertex_handle(h).idx(), b = mesh.to_vertex_handle(h).idx();
    if (arc_edge[e.idx()] || near_node[a] || near_node[b] || mesh.is_boundary(e)) continue;
    layout.feature_edges.push_back({a, b});
    feature_face = mesh.face_handle(h).idx();
    break;
  }
  ASSERT_GE(feature_face, 0);
  const LayoutTopology topo = build_topology(mesh, layout);
  const CrossField field = compute_cross_field(mesh, g, layout, topo);
  const std::vector<int>& p = field.period_jump;
  auto shifted = [&](double phi) {
    std::vector<double> t = field.theta;
    for (double& x : t) x += phi;
    return t;
  };
  auto symbols = [&](const std::vector<double>& theta) {
    return label_layout(mesh, g, layout, topo, p, theta).symbol;
  };
  auto prepared = [&] {
    return std::make_unique<ParamSolver>(mesh, g, layout, topo, p, field.theta, ParamOptions{},
                                         nullptr, /*solve_now=*/false);
  };

  // A half turn: every label moves by 2, the rows stay. Adopted: the labels for θ + π and the
  // solution of a solver built for θ + π.
  {
    const std::vector<double> theta = shifted(M_PI);
    const std::vector<int> s0 = symbols(field.theta), s1 = symbols(theta);
    ASSERT_NE(s0, s1) << "the half turn should move the labels";
    for (size_t h = 0; h < s0.size(); ++h) ASSERT_EQ((s0[h] + 2) % 4, s1[h]);
    auto solver = prepared();
    ASSERT_TRUE(solver->adopt_field(mesh, g, layout, topo, p, theta));
    EXPECT_EQ(solver->labeling().symbol, s1);
    const Parameterization& adopted = solver->solve(mesh, g, theta);
    ParamSolver built(mesh, g, layout, topo, p, theta);
    EXPECT_LT(corner_gap(built.result().corner_uv, adopted.corner_uv), 1e-12);
    EXPECT_NEAR(adopted.energy, built.result().energy, 1e-12 * built.result().energy);
    EXPECT_EQ(adopted.foldovers, built.result().foldovers);
  }
  // A quarter turn swaps u and v on every arc: other rows.
  {
    const std::vector<double> theta = shifted(M_PI / 2);
    const std::vector<int> s0 = symbols(field.theta), s1 = symbols(theta);
    ASSERT_NE(s0[0] % 2, s1[0] % 2) << "the quarter turn should change the labels' parity";
    auto solver = prepared();
    EXPECT_FALSE(solver->adopt_field(mesh, g, layout, topo, p, theta));
    EXPECT_EQ(solver->labeling().symbol, s0);  // unchanged
  }
  // The feature edge's face turned by a quarter: same labels, the feature row changes.
  {
    std::vector<double> theta = field.theta;
    theta[feature_face] += M_PI / 2;
    ASSERT_EQ(symbols(theta), symbols(field.theta));
    auto solver = prepared();
    EXPECT_FALSE(solver->adopt_field(mesh, g, layout, topo, p, theta));
  }
  // Other period jumps (one edge's jump by a full turn, the same modulo 4).
  {
    std::vector<int> other = p;
    other[0] += 4;
    auto solver = prepared();
    EXPECT_FALSE(solver->adopt_field(mesh, g, layout, topo, other, field.theta));
    EXPECT_TRUE(solver->adopt_field(mesh, g, layout, topo, p, field.theta));
  }
}

// Pipelines use the solvers set up ahead (a fresh one the reference rotation's, a continued one
// the solver set up beside update_layout) and get the parameterization they would get without
// them: a solver built for the final field, and a continued pipeline without the second thread.
TEST(ReuseParam, PreparedSolversGiveTheSameParameterization) {
  const auto cs = test::cube_sphere(8, Vec3(2.0, 1.0, 0.6));
  const Example ex{cs.mesh, cs.layout};
  PipelineOptions options;
  options.second_thread_min_faces = 0;  // a small mesh
  ASSERT_GT(options.field.max_cluster_faces, 0) << "split clusters: the reference rotation";
  Pipeline first(ex.mesh, ex.layout, options);
  first.compute_field();
  const Parameterization& r0 = first.compute_parameterization();
  EXPECT_TRUE(first.param_solver_prepared());
  {
    ParamSolver built(first.mesh(), first.geometry(), first.layout(), first.topology(),
                      first.field()->period_jump, first.field()->theta, options.param);
    EXPECT_LT(corner_gap(built.result().corner_uv, r0.corner_uv), 1e-12);
    EXPECT_EQ(built.labeling().symbol, first.param_solver()->labeling().symbol);
  }
  PipelineOptions one_thread = options;
  one_thread.param.second_thread = false;
  Pipeline first_one(ex.mesh, ex.layout, one_thread);
  first_one.compute_parameterization();
  int adopted = 0;
  for (unsigned seed : {1u, 2u, 3u}) {
    const Layout moved = moved_layout(ex.mesh, ex.layout, seed);
    const TriMesh mesh = relocated(ex.mesh, ex.layout, 0.3, seed);
    Pipeline continued(mesh, moved, first);
    continued.compute_field();
    const Parameterization& r = continued.compute_parameterization();
    Pipeline plain(mesh, moved, first_one);
    plain.compute_field();
    const Parameterization& q = plain.compute_parameterization();
    EXPECT_FALSE(plain.param_solver_prepared());
    adopted += continued.param_solver_prepared();
    EXPECT_LT(corner_gap(q.corner_uv, r.corner_uv), 1e-12) << "seed " << seed;
    EXPECT_EQ(q.foldovers, r.foldovers) << "seed " << seed;
    EXPECT_EQ(plain.param_solver()->labeling().symbol, continued.param_solver()->labeling().symbol);
    EXPECT_EQ(plain.param_solver()->labeling().geometric_mismatches,
              continued.param_solver()->labeling().geometric_mismatches);
  }
  EXPECT_GT(adopted, 0) << "no continued pipeline adopted its prepared solver";
  // With the default threshold a mesh this small sets the solver up after the field.
  const PipelineOptions defaults;
  ASSERT_LT(static_cast<int>(ex.mesh.n_faces()), defaults.second_thread_min_faces);
  Pipeline first_default(ex.mesh, ex.layout, defaults);
  first_default.compute_parameterization();
  Pipeline later(ex.mesh, moved_layout(ex.mesh, ex.layout, 1), first_default);
  later.compute_parameterization();
  EXPECT_FALSE(later.param_solver_prepared());
}

// PipelineOptions::order_vertices: the Pipeline orders the mesh's vertices once (nested
// dissection, on its second thread), its parameterization's analysis takes that order, the
// result is the AMD-ordered one up to round-off, and the pipelines continued from it share the
// order, also when they are made before it was taken. Small meshes (below
// second_thread_min_faces) and order_vertices = false keep AMD.
TEST(ReuseParam, PipelineOrdersTheVerticesOnceForItsSolvers) {
  const auto cs = test::cube_sphere(8, Vec3(2.0, 1.0, 0.6));
  const Example ex{cs.mesh, cs.layout};
  PipelineOptions options;
  options.second_thread_min_faces = 0;  // a small mesh
  ASSERT_TRUE(options.order_vertices);
  ASSERT_TRUE(pipeline_orders_vertices(options, static_cast<int>(ex.mesh.n_faces())));
  { Pipeline dropped(ex.mesh, ex.layout, options); }  // waits for its ordering thread
  Pipeline ordered(ex.mesh, ex.layout, options);
  const Parameterization& a = ordered.compute_parameterization();
  const auto& order = ordered.options().param.vertex_order;
  ASSERT_TRUE(order);
  EXPECT_EQ(*order, vertex_nested_dissection(ordered.geometry()));
  EXPECT_GE(ordered.param_solver()->linear_solver().stats().hinted_analyses, 1);

  PipelineOptions off = options;
  off.order_vertices = false;
  EXPECT_FALSE(pipeline_orders_vertices(off, static_cast<int>(ex.mesh.n_faces())));
  Pipeline plain(ex.mesh, ex.layout, off);
  const Parameterization& b = plain.compute_parameterization();
  EXPECT_FALSE(plain.options().param.vertex_order);
  EXPECT_EQ(plain.param_solver()->linear_solver().stats().hinted_analyses, 0);
  EXPECT_LT(corner_gap(a.corner_uv, b.corner_uv), 1e-9);
  EXPECT_NEAR(a.energy, b.energy, 1e-9 * b.energy);

  const Layout moved = moved_layout(ex.mesh, ex.layout, 1);
  const TriMesh mesh = relocated(ex.mesh, ex.layout, 0.3, 1);
  Pipeline continued(mesh, moved, ordered);
  continued.compute_parameterization();
  EXPECT_EQ(continued.options().param.vertex_order, order) << "not the same order object";
  Pipeline early(ex.mesh, ex.layout, options);  // continued before it took its order
  Pipeline continued_early(mesh, moved, early);
  continued_early.compute_parameterization();
  ASSERT_TRUE(continued_early.options().param.vertex_order);
  EXPECT_EQ(*continued_early.options().param.vertex_order, *order);
  EXPECT_GE(continued_early.param_solver()->linear_solver().stats().hinted_analyses, 1);

  Pipeline small(ex.mesh, ex.layout);  // default threshold
  ASSERT_LT(static_cast<int>(ex.mesh.n_faces()), PipelineOptions{}.second_thread_min_faces);
  small.compute_parameterization();
  EXPECT_FALSE(small.options().param.vertex_order);
}

// The vertex order on a layout whose cut merges wedges along long seams: the pig's quad mesh
// refined 3 times (as `import-quads --refine 3`, 41400 faces, 942 nodes), where most merged
// unknowns have about 70 entries per column. The parameterization's ordering from the vertex
// order must keep about AMD's fill on its own (no rescue by the solver's fill check): an
// earlier ordering sent those unknowns last, unordered, with 13 times AMD's fill and a 3.3 s
// factorization instead of 0.06 s.
TEST(ReuseParam, VertexOrderKeepsTheFillOfAmdWhereSeamsMergeManyWedges) {
  const std::string dir = test::shared_meshes_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/data/meshes is absent";
  QuadImportOptions import;
  import.refine = 3;
  const QuadImportResult in =
      import_quads(load_poly_mesh(dir + "/animals_basemesh/pig_pig.obj"), nullptr, import);
  PipelineOptions options;
  ASSERT_TRUE(pipeline_orders_vertices(options, static_cast<int>(in.mesh.n_faces())));
  Pipeline p(in.mesh, in.layout, options);
  p.compute_parameterization();
  const ParamSolver& solver = *p.param_solver();
  const SpdSolverStats& stats = solver.linear_solver().stats();
  EXPECT_GE(stats.hinted_analyses, 1);
  EXPECT_EQ(stats.rejected_hints, 0);
  // AMD (CHOLMOD's default) on the same reduced matrix.
  ReducedAssembly assembly(solver.cut_graph().corner_wedge, solver.cut_graph().wedges,
                           solver.constraints().variables, solver.reduction().Z);
  const Eigen::Matrix3d block = Eigen::Matrix3d::Identity() * 2 - Eigen::Matrix3d::Ones() / 2;
  for (int f = 0; f < p.geometry().n_faces; ++f) assembly.add_face(f, block, block);
  assembly.reduce();
  SpdSolver amd("AMD");
  amd.analyze(assembly.A());
  std::printf(
      "[stat] pig, refine 3: %ld unknowns, nnz(A) %ld, nnz(L) %.0f with the vertex "
      "order, %.0f with AMD\n",
      static_cast<long>(assembly.A().rows()), static_cast<long>(assembly.A().nonZeros()),
      stats.factor_nonzeros, amd.stats().factor_nonzeros);
  EXPECT_LE(stats.factor_nonzeros, 1.5 * amd.stats().factor_nonzeros);
}

}  // namespace
}  // namespace qs
