// Fold-over removal by strict orientation constraints (issue #5 item 6, docs/design.md,
// "Orientation constraints"): the tri-sector QP solver on small hand-made problems, the constrained
// parameterization on a folding synthetic layout (equality constraints still exact), the node
// optimizer's final solve on the bundled example and on real layouts.
#include "core/param/orientation.h"

#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/base/errors.h"
#include "core/import/perturb.h"
#include "core/import/quad_import.h"
#include "core/layout/layout_io.h"
#include "core/mesh/mesh_checks.h"
#include "core/mesh/mesh_io.h"
#include "core/nodeopt/gradient.h"
#include "core/nodeopt/optimizer.h"
#include "core/pipeline/pipeline.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

// ---------------------------------------------------------------------------------------------
// (a) the QP on one triangle: corners P0 = (0, 0), P1 = (1, 0) fixed (in z0), P2 free or half
// free (columns of Z).

struct OneTriangle {
  TriMesh mesh;
  GeometryCache geometry;
  std::vector<double> theta;
  std::vector<int> corner_wedge{0, 1, 2};
};

OneTriangle one_triangle() {
  OneTriangle t;
  const auto a = t.mesh.add_vertex(Vec3(0, 0, 0));
  const auto b = t.mesh.add_vertex(Vec3(1, 0, 0));
  const auto c = t.mesh.add_vertex(Vec3(0.5, 0.8, 0));
  t.mesh.add_face(a, b, c);
  t.geometry = build_geometry(t.mesh);
  // Field along the x axis: the ideal map is the identity up to the face frame (r = first edge).
  t.theta = {0.0};
  return t;
}

TEST(OrientationQp, PullsAFoldedCornerBackInsideItsSector) {
  OneTriangle t = one_triangle();
  Reduction red;
  red.z0 = Eigen::VectorXd::Zero(6);
  red.z0(2) = 1.0;  // P1 = (1, 0)
  red.Z.resize(6, 2);
  red.Z.insert(4, 0) = 1.0;  // P2 = (y0, y1)
  red.Z.insert(5, 1) = 1.0;
  // Energy |P2 − (0.5, −1)|²: the unconstrained optimum folds the triangle.
  Eigen::SparseMatrix<double> A(2, 2);
  A.insert(0, 0) = 1.0;
  A.insert(1, 1) = 1.0;
  const Eigen::VectorXd b = Eigen::Vector2d(0.5, -1.0);
  const Eigen::VectorXd y0 = b;
  OrientationOptions o;
  OrientationReport rep;
  const Eigen::VectorXd y =
      solve_oriented(t.mesh, t.geometry, t.theta, t.corner_wedge, red, A, b, y0, o, &rep);
  EXPECT_EQ(rep.foldovers_before, 1);
  EXPECT_EQ(rep.foldovers_after, 0);
  EXPECT_EQ(rep.constrained_faces, 1);
  EXPECT_GT(rep.iterations, 0);
  // The ideal triangle (0,0), (1,0), (0.5,0.8) and the target are symmetric about u = 0.5, so
  // is the optimum; it is as low as the sector constraints allow: above the fixed edge (the
  // face is positively oriented) and below the ideal apex (the energy pulls it down).
  EXPECT_NEAR(y(0), 0.5, 1e-6);
  EXPECT_GT(y(1), 0.0);
  EXPECT_LT(y(1), 0.8);
  // A weaker pull gives a higher, still constrained optimum; a pull upwards none at all.
  const Eigen::VectorXd b2 = Eigen::Vector2d(0.5, -0.2);
  const Eigen::VectorXd y2 =
      solve_oriented(t.mesh, t.geometry, t.theta, t.corner_wedge, red, A, b2, b2, o, &rep);
  EXPECT_EQ(rep.foldovers_after, 0);
  EXPECT_NEAR(y2(1), y(1), 1e-6) << "the same constraint is active";
}

TEST(OrientationQp, InfeasibleConstraintsThrowSolverError) {
  OneTriangle t = one_triangle();
  Reduction red;
  red.z0 = Eigen::VectorXd::Zero(6);
  red.z0(2) = 1.0;   // P1 = (1, 0)
  red.z0(5) = -1.0;  // P2 = (y, −1): always folded
  red.Z.resize(6, 1);
  red.Z.insert(4, 0) = 1.0;
  Eigen::SparseMatrix<double> A(1, 1);
  A.insert(0, 0) = 1.0;
  const Eigen::VectorXd b = Eigen::VectorXd::Constant(1, 0.5);
  OrientationReport rep;
  EXPECT_THROW(solve_oriented(t.mesh, t.geometry, t.theta, t.corner_wedge, red, A, b, b, {}, &rep),
               SolverError);
  EXPECT_TRUE(rep.ran);
  EXPECT_FALSE(rep.message.empty());
}

TEST(OrientationQp, NoFoldsReturnsTheUnconstrainedSolution) {
  OneTriangle t = one_triangle();
  Reduction red;
  red.z0 = Eigen::VectorXd::Zero(6);
  red.z0(2) = 1.0;
  red.Z.resize(6, 2);
  red.Z.insert(4, 0) = 1.0;
  red.Z.insert(5, 1) = 1.0;
  Eigen::SparseMatrix<double> A(2, 2);
  A.insert(0, 0) = 1.0;
  A.insert(1, 1) = 1.0;
  const Eigen::VectorXd b = Eigen::Vector2d(0.4, 0.9);
  OrientationReport rep;
  const Eigen::VectorXd y =
      solve_oriented(t.mesh, t.geometry, t.theta, t.corner_wedge, red, A, b, b, {}, &rep);
  EXPECT_EQ(rep.foldovers_before, 0);
  EXPECT_EQ(rep.iterations, 0);
  EXPECT_EQ((y - b).norm(), 0.0);
}

// solution_frame_angles on a flat fan of six triangles, each with its own three wedges, whose
// field runs along the global x axis (θ_f in each face's own 2D frame) and whose map is the
// global (x, y) turned by φ (40°) and scaled by 2: every face's rotation from the field to the
// map is φ, so its Q_k at the returned angle are parallel to its corner offsets; a turn of more
// than 45° is clamped to 45°. One face mirrored
// (folded) takes its neighbours' rotation φ; with every face folded, the field frame stays.
TEST(OrientationQp, SolutionFrameTurnsTheSectorsWithTheMap) {
  TriMesh mesh;
  const auto center = mesh.add_vertex(Vec3(0, 0, 0));
  std::vector<TriMesh::VertexHandle> rim;
  for (int k = 0; k < 6; ++k)
    rim.push_back(mesh.add_vertex(Vec3(std::cos(k * M_PI / 3), 0.8 * std::sin(k * M_PI / 3), 0)));
  for (int k = 0; k < 6; ++k) mesh.add_face(center, rim[k], rim[(k + 1) % 6]);
  const GeometryCache g = build_geometry(mesh);
  const int nf = g.n_faces;
  const double phi = 0.7;
  std::vector<double> theta(nf);
  std::vector<int> corner_wedge(3 * nf);
  Eigen::VectorXd x(6 * nf);
  for (int f = 0; f < nf; ++f) {
    const auto p = face_corners_2d(mesh, g, f);
    const Vec3 a = mesh.point(mesh.vertex_handle(g.face_vertices[f][0]));
    const Vec3 b = mesh.point(mesh.vertex_handle(g.face_vertices[f][1]));
    // The face frame's angle α_f in the global plane; the global x axis is at −α_f in it.
    const double alpha =
        std::atan2(b[1] - a[1], b[0] - a[0]) - std::atan2(p[1][1] - p[0][1], p[1][0] - p[0][0]);
    theta[f] = -alpha;
    for (int k = 0; k < 3; ++k) {
      corner_wedge[3 * f + k] = 3 * f + k;
      const Vec3 q = mesh.point(mesh.vertex_handle(g.face_vertices[f][k]));
      x(2 * (3 * f + k)) = 2 * (std::cos(phi) * q[0] - std::sin(phi) * q[1]);
      x(2 * (3 * f + k) + 1) = 2 * (std::sin(phi) * q[0] + std::cos(phi) * q[1]);
    }
  }
  auto turn = [](double a) { return std::remainder(a, 2 * M_PI); };
  {
    const std::vector<double> t = solution_frame_angles(g, theta, corner_wedge, x);
    ASSERT_EQ(static_cast<int>(t.size()), nf);
    const auto ideal = ideal_corner_offsets(mesh, g, t);
    for (int f = 0; f < nf; ++f) {
      EXPECT_NEAR(turn(t[f] - theta[f] + phi), 0.0, 1e-12) << "face " << f;
      const Eigen::Vector2d c =
          (x.segment<2>(6 * f) + x.segment<2>(6 * f + 2) + x.segment<2>(6 * f + 4)) / 3;
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector2d d = x.segment<2>(2 * (3 * f + k)) - c;
        const Eigen::Vector2d q(ideal[f][k][0], ideal[f][k][1]);
        EXPECT_NEAR(d.x() * q.y() - d.y() * q.x(), 0.0, 1e-12 * d.norm() * q.norm());
        EXPECT_GT(d.dot(q), 0.0);
      }
    }
    // The field frame's own sectors are turned by −φ against the map.
    const auto field = ideal_corner_offsets(mesh, g, theta);
    const Eigen::Vector2d d =
        x.segment<2>(0) - (x.segment<2>(0) + x.segment<2>(2) + x.segment<2>(4)) / 3;
    EXPECT_NEAR(std::atan2(d.y(), d.x()) - std::atan2(field[0][0][1], field[0][0][0]), phi, 1e-12);
  }
  // A turn beyond 45° is clamped to 45° (the field's winding around the vertices is kept).
  {
    Eigen::VectorXd steep(x.size());
    const double psi = 1.2 - phi;  // turns the map by 1.2 rad from the field in all
    for (int c = 0; c < 3 * nf; ++c) {
      const double u = x(2 * c), v = x(2 * c + 1);
      steep(2 * c) = std::cos(psi) * u - std::sin(psi) * v;
      steep(2 * c + 1) = std::sin(psi) * u + std::cos(psi) * v;
    }
    const std::vector<double> t = solution_frame_angles(g, theta, corner_wedge, steep);
    for (int f = 0; f < nf; ++f) EXPECT_NEAR(turn(t[f] - theta[f] + M_PI / 4), 0.0, 1e-12) << f;
  }
  // Face 2 mirrored across its first corner's u: folded; it takes φ from faces 1 and 3.
  Eigen::VectorXd folded = x;
  for (int k = 0; k < 3; ++k) folded(2 * (6 + k)) = 2 * x(2 * 6) - x(2 * (6 + k));
  ASSERT_EQ(count_foldovers(corner_wedge, folded), 1);
  const std::vector<double> t = solution_frame_angles(g, theta, corner_wedge, folded);
  for (int f = 0; f < nf; ++f) EXPECT_NEAR(turn(t[f] - theta[f] + phi), 0.0, 1e-12) << f;
  // Every face folded: nothing to take a rotation from.
  Eigen::VectorXd all = x;
  for (int c = 0; c < 3 * nf; ++c) all(2 * c) = -x(2 * c);
  ASSERT_EQ(count_foldovers(corner_wedge, all), nf);
  EXPECT_EQ(solution_frame_angles(g, theta, corner_wedge, all), theta);
  EXPECT_THROW(solution_frame_angles(g, theta, corner_wedge, x.head(4)), InvalidInputError);
}

// ---------------------------------------------------------------------------------------------
// (b) the constrained parameterization keeps every equality constraint exact

// Recovers the free unknowns y from the corner values (least squares on the wedge rows of Z)
// and returns the largest violation of the equality constraints by x = Z·y + z0, plus (in
// *fit) the largest misfit of the wedge values, which must be ≈ 0 for the check to mean that
// the corner values satisfy every constraint.
double constraint_violation(const ParamSolver& solver, const Parameterization& p, double* fit) {
  const Reduction& red = solver.reduction();
  const std::vector<int>& cw = solver.cut_graph().corner_wedge;
  const int wedges = solver.cut_graph().wedges;
  Eigen::VectorXd xw = Eigen::VectorXd::Zero(2 * wedges);
  for (size_t c = 0; c < cw.size(); ++c) {
    xw(2 * cw[c]) = p.corner_uv[c][0];
    xw(2 * cw[c] + 1) = p.corner_uv[c][1];
  }
  const Eigen::SparseMatrix<double> Zw = red.Z.topRows(2 * wedges);
  const Eigen::SparseMatrix<double> N = Zw.transpose() * Zw;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(N);
  const Eigen::VectorXd y = ldlt.solve(Zw.transpose() * (xw - red.z0.head(2 * wedges)));
  const Eigen::VectorXd x = red.Z * y + red.z0;
  *fit = (x.head(2 * wedges) - xw).lpNorm<Eigen::Infinity>();
  double worst = 0;
  for (const LinearRow& row : solver.constraints().rows) {
    double r = -row.rhs;
    for (auto [v, c] : row.terms) r += c * x(v);
    worst = std::max(worst, std::abs(r));
  }
  return worst;
}

// The cube-on-sphere layout with its nodes displaced `rings` rings: the unconstrained
// parameterization folds.
Layout displaced(const test::MeshAndLayout& in, int rings, unsigned seed) {
  PerturbLayoutOptions po;
  po.rings = rings;
  po.seed = seed;
  return perturb_layout(in.mesh, in.layout, po).layout;
}

// Largest difference of a corner coordinate between two parameterizations of one mesh.
double max_corner_difference(const Parameterization& a, const Parameterization& b) {
  EXPECT_EQ(a.corner_uv.size(), b.corner_uv.size());
  double worst = 0;
  for (size_t c = 0; c < a.corner_uv.size() && c < b.corner_uv.size(); ++c)
    for (int k = 0; k < 2; ++k)
      worst = std::max(worst, std::abs(a.corner_uv[c][k] - b.corner_uv[c][k]));
  return worst;
}

PipelineOptions with_orientation(int dense_max_rows = OrientationOptions{}.dense_max_rows) {
  PipelineOptions o;
  o.param.orientation.enabled = true;
  o.param.orientation.dense_max_rows = dense_max_rows;
  o.param.orientation.dense_cost_ratio = 1e12;  // the dense solver whenever it is allowed
  return o;
}

TEST(OrientationParam, RemovesFoldsAndKeepsEqualityConstraintsExact) {
  const auto in = test::cube_sphere(6);
  const Layout layout = displaced(in, 4, 1);
  Pipeline plain(in.mesh, layout, PipelineOptions{});
  const Parameterization& before = plain.compute_parameterization();
  Pipeline oriented(in.mesh, layout, with_orientation());
  const Parameterization& after = oriented.compute_parameterization();
  const OrientationReport& rep = after.orientation;
  std::printf(
      "[stat] displaced sphere: fold-overs %d -> %d, E %.6g -> %.6g, %d faces, %d rounds, "
      "%d iterations (%s)\n",
      before.foldovers, after.foldovers, before.energy, after.energy, rep.constrained_faces,
      rep.rounds, rep.iterations, rep.dense ? "dense" : "sparse");
  ASSERT_GT(before.foldovers, 5) << "the test case must fold without the constraints";
  EXPECT_TRUE(rep.ran);
  EXPECT_TRUE(rep.success) << rep.message;
  EXPECT_EQ(rep.foldovers_before, before.foldovers);
  EXPECT_EQ(after.foldovers, 0);
  for (int f = 0; f < static_cast<int>(in.mesh.n_faces()); ++f)
    ASSERT_GT(param_signed_area2(after.corner_uv, f), 0.0) << "face " << f;
  // Constrained optimum: never below the unconstrained one, and only moderately above.
  EXPECT_GE(after.energy, before.energy * (1 - 1e-12));
  EXPECT_LE(after.energy, before.energy * 1.15);
  EXPECT_NEAR(rep.energy_before, before.energy, 1e-9 * before.energy);
  EXPECT_NEAR(rep.energy_after, after.energy, 1e-9 * after.energy);
  // Seams, node connections and the fixed point still hold exactly.
  double fit = 0;
  const double violation = constraint_violation(*oriented.param_solver(), after, &fit);
  EXPECT_LT(fit, 1e-9);
  EXPECT_LT(violation, 1e-9);
  // Fewer faces than the mesh are constrained (folded faces and their rings only).
  EXPECT_GT(rep.constrained_faces, 0);
  EXPECT_LT(rep.constrained_faces, static_cast<int>(in.mesh.n_faces()));
  // The layout is still realized: every arc traces.
  EXPECT_TRUE(oriented.extract().structurally_equivalent);
}

TEST(OrientationParam, DenseDualAndSparsePrimalSolversAgree) {
  const auto in = test::cube_sphere(6);
  const Layout layout = displaced(in, 3, 2);
  Pipeline dense(in.mesh, layout, with_orientation());
  PipelineOptions sparse_options = with_orientation(0);
  sparse_options.param.orientation.all_faces_after_rounds = 0;  // the same constraint set
  Pipeline sparse(in.mesh, layout, sparse_options);
  const Parameterization& a = dense.compute_parameterization();
  const Parameterization& b = sparse.compute_parameterization();
  ASSERT_GT(a.orientation.foldovers_before, 0);
  EXPECT_TRUE(a.orientation.dense);
  EXPECT_FALSE(b.orientation.dense);
  EXPECT_GT(b.orientation.sparse_factorizations, 0);
  EXPECT_EQ(a.foldovers, 0);
  EXPECT_EQ(b.foldovers, 0);
  EXPECT_NEAR(a.energy, b.energy, 1e-7 * a.energy);
  EXPECT_LT(max_corner_difference(a, b), 1e-4);
}

// ParamOptions::vertex_order also orders the sparse rounds' normal matrices: the same
// constrained optimum as with CHOLMOD's own ordering, to the solver's tolerance.
TEST(OrientationParam, VertexOrderGivesTheSameSparseSolve) {
  const auto in = test::cube_sphere(6);
  const Layout layout = displaced(in, 3, 2);
  PipelineOptions plain_options = with_orientation(0);
  plain_options.param.orientation.all_faces_after_rounds = 0;
  PipelineOptions ordered_options = plain_options;
  ordered_options.param.vertex_order =
      std::make_shared<const std::vector<int>>(vertex_nested_dissection(build_geometry(in.mesh)));
  ASSERT_EQ(ordered_options.param.vertex_order->size(), in.mesh.n_vertices());
  Pipeline plain(in.mesh, layout, plain_options), ordered(in.mesh, layout, ordered_options);
  const Parameterization& a = plain.compute_parameterization();
  const Parameterization& b = ordered.compute_parameterization();
  ASSERT_GT(a.orientation.foldovers_before, 0);
  EXPECT_FALSE(b.orientation.dense);
  EXPECT_GT(b.orientation.sparse_factorizations, 0);
  EXPECT_EQ(ordered.param_solver()->linear_solver().stats().hinted_analyses, 1);
  EXPECT_EQ(a.orientation.ordered_rounds, 0);
  EXPECT_EQ(b.orientation.ordered_rounds, b.orientation.rounds);
  EXPECT_EQ(a.foldovers, 0);
  EXPECT_EQ(b.foldovers, 0);
  EXPECT_NEAR(a.energy, b.energy, 1e-7 * a.energy);
  EXPECT_LT(max_corner_difference(a, b), 1e-4);
}

// OrientationOptions::observer is polled inside the solve, by both solvers: an observer that
// asks to cancel after k polls stops it with qs::Cancelled (no result, no SolverError), and one
// that never does sees at least one poll per interior-point iteration.
TEST(OrientationParam, TheSolvePollsForCancellation) {
  struct CountingObserver : Observer {
    mutable int polls = 0;
    int cancel_after = 1 << 30;
    bool should_cancel() const override { return ++polls > cancel_after; }
  };
  const auto in = test::cube_sphere(6);
  const Layout layout = displaced(in, 3, 2);
  for (const int dense_rows : {OrientationOptions{}.dense_max_rows, 0}) {
    SCOPED_TRACE(dense_rows > 0 ? "dense dual solver" : "sparse primal solver");
    CountingObserver counting;
    PipelineOptions o = with_orientation(dense_rows);
    o.param.orientation.observer = &counting;
    Pipeline full(in.mesh, layout, o);
    const Parameterization& p = full.compute_parameterization();
    ASSERT_GT(p.orientation.iterations, 1);
    EXPECT_EQ(p.foldovers, 0);
    EXPECT_GE(counting.polls, p.orientation.iterations);
    CountingObserver cancelling;
    cancelling.cancel_after = 1;  // the first round starts; its first loop iteration stops
    o.param.orientation.observer = &cancelling;
    Pipeline stopped(in.mesh, layout, o);
    EXPECT_THROW(stopped.compute_parameterization(), Cancelled);
    EXPECT_EQ(cancelling.polls, 2);
  }
}

// After a sparse round that left fold-overs outside its set (all_faces_after_rounds = 1 here),
// every face is constrained in the next QP. Its feasible set lies inside that of any smaller
// set, so its optimum is not below the growing rounds' result; it must still remove every
// fold-over and keep the equality constraints exact.
TEST(OrientationParam, AllFacesAfterAnUnfinishedSparseRound) {
  const auto in = test::cube_sphere(6);
  const Layout layout = displaced(in, 4, 1);
  Pipeline plain(in.mesh, layout, PipelineOptions{});
  const Parameterization& before = plain.compute_parameterization();
  ASSERT_GT(before.foldovers, 5) << "the test case must fold without the constraints";
  PipelineOptions all_options = with_orientation(0);  // no dense solver: the sparse path
  all_options.param.orientation.all_faces_after_rounds = 1;
  Pipeline all(in.mesh, layout, all_options);
  const Parameterization& a = all.compute_parameterization();
  PipelineOptions rounds_options = with_orientation(0);
  rounds_options.param.orientation.all_faces_after_rounds = 0;
  Pipeline rounds(in.mesh, layout, rounds_options);
  const Parameterization& r = rounds.compute_parameterization();
  std::printf(
      "[stat] displaced sphere, sparse solver: all faces %d fold-overs, E %.6g, %d iterations; "
      "rounds %d fold-overs, E %.6g, %d rounds, %d iterations, %d faces\n",
      a.foldovers, a.energy, a.orientation.iterations, r.foldovers, r.energy, r.orientation.rounds,
      r.orientation.iterations, r.orientation.constrained_faces);
  EXPECT_TRUE(a.orientation.all_faces);
  EXPECT_FALSE(r.orientation.all_faces);
  EXPECT_TRUE(a.orientation.success) << a.orientation.message;
  ASSERT_GE(r.orientation.rounds, 2) << "the case must need more than one growing round";
  EXPECT_EQ(a.orientation.rounds, 2);
  EXPECT_EQ(a.orientation.constrained_faces + a.orientation.skipped_faces,
            static_cast<int>(in.mesh.n_faces()));
  EXPECT_LT(r.orientation.constrained_faces, a.orientation.constrained_faces);
  EXPECT_EQ(a.foldovers, 0);
  for (int f = 0; f < static_cast<int>(in.mesh.n_faces()); ++f)
    ASSERT_GT(param_signed_area2(a.corner_uv, f), 0.0) << "face " << f;
  EXPECT_GE(a.energy, before.energy * (1 - 1e-12));
  if (r.foldovers == 0) {
    EXPECT_GE(a.energy, r.energy * (1 - 1e-7));
  }
  EXPECT_LE(a.energy, before.energy * 1.15);
  double fit = 0;
  EXPECT_LT(constraint_violation(*all.param_solver(), a, &fit), 1e-9);
  EXPECT_LT(fit, 1e-9);
  EXPECT_TRUE(all.extract().structurally_equivalent);
}

TEST(OrientationParam, WithoutFoldsTheSolveIsUnchanged) {
  const auto in = test::cube_sphere(6);
  Pipeline plain(in.mesh, in.layout, PipelineOptions{});
  Pipeline oriented(in.mesh, in.layout, with_orientation());
  const Parameterization& a = plain.compute_parameterization();
  const Parameterization& b = oriented.compute_parameterization();
  ASSERT_EQ(a.foldovers, 0);
  EXPECT_FALSE(b.orientation.ran);
  EXPECT_EQ(a.energy, b.energy);
  EXPECT_EQ(a.corner_uv, b.corner_uv);
}

// ---------------------------------------------------------------------------------------------
// (c) the node optimizer's last solve

TEST(OrientationNodeOpt, FoldsLeftByTheDescentAreRemovedByConstraintsNotStiffening) {
  const auto in = test::cube_sphere(6);
  const Layout layout = displaced(in, 4, 1);
  NodeOptOptions no;
  no.descent.max_steps =
      0;  // no descent: the fold-overs of the displaced layout reach the last solve
  const NodeOptResult r = optimize_nodes(in.mesh, layout, PipelineOptions{}, no);
  std::printf("[stat] node optimizer: fold-overs %d -> %d (%s), E %.6g -> %.6g\n",
              r.foldovers_descent, r.foldovers_final,
              r.orientation_constraints ? "orientation" : "stiffening", r.E_descent, r.E_final);
  ASSERT_GT(r.foldovers_descent, 0);
  EXPECT_EQ(r.foldovers_final, 0);
  EXPECT_TRUE(r.orientation_constraints);
  EXPECT_TRUE(r.orientation.success);
  EXPECT_TRUE(r.face_weights.empty()) << "stiffening is only the fallback";
  EXPECT_EQ(r.stiffening_iterations, 0);
  EXPECT_GE(r.E_final, r.E_descent * (1 - 1e-12));
  ASSERT_FALSE(r.reports.empty());
  EXPECT_EQ(r.reports.back().phase, "orientation");
  EXPECT_EQ(r.reports.back().foldovers, 0);
  // Re-solving the result with the reported options reproduces the final solve.
  PipelineOptions again;
  again.param.orientation = r.orientation_options;
  ASSERT_TRUE(again.param.orientation.enabled);
  Pipeline p(r.mesh, r.layout, again);
  const Parameterization& par = p.compute_parameterization();
  EXPECT_EQ(par.foldovers, 0);
  EXPECT_NEAR(unweighted_energy(p.mesh(), p.geometry(), p.field()->theta, par, {}), r.E_final,
              1e-9 * r.E_final);
  ASSERT_TRUE(r.pipeline && r.pipeline->parameterization());
  EXPECT_EQ(r.pipeline->parameterization()->foldovers, 0);
  // Disabled: no constrained solve; stiffening alone takes over.
  no.folds.orientation = false;
  const NodeOptResult s = optimize_nodes(in.mesh, layout, PipelineOptions{}, no);
  EXPECT_FALSE(s.orientation.ran);
  EXPECT_FALSE(s.orientation_constraints);
  EXPECT_EQ(s.foldovers_descent, r.foldovers_descent);
  std::printf("[stat] stiffening alone: fold-overs %d -> %d, E %.6g\n", s.foldovers_descent,
              s.foldovers_final, s.E_final);
}

// The fold-over removal gives up a constrained solve that is infeasible (InfeasibleLayoutError,
// SolverError: NodeOptResult::orientation keeps the message) but lets every other error through
// with its message: invalid orientation options in the given PipelineOptions, which only the
// constrained solve reads, are the caller's error, not a failed attempt.
TEST(OrientationNodeOpt, InvalidOrientationOptionsAreNotAFailedAttempt) {
  const auto in = test::cube_sphere(6);
  const Layout layout = displaced(in, 4, 1);
  NodeOptOptions no;
  no.descent.max_steps = 0;  // the fold-overs of the displaced layout reach the removal
  PipelineOptions options;
  options.param.orientation.max_iterations = 0;
  try {
    const NodeOptResult r = optimize_nodes(in.mesh, layout, options, no);
    FAIL() << "taken as a failed attempt: " << r.orientation.message;
  } catch (const InfeasibleLayoutError& e) {
    FAIL() << "not an infeasible layout: " << e.what();
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("orientation constraints: invalid options"),
              std::string::npos)
        << e.what();
  }
}

// The command line reports the counts before / after and the method, and --no-orientation
// leaves the fold-overs to stiffening.
TEST(OrientationNodeOpt, CommandLineReportsFoldRemoval) {
  if (!std::filesystem::exists(test::cli_path())) GTEST_SKIP() << "quadsketch-cli not built";
  const auto in = test::cube_sphere(6);
  const std::string dir = test::temp_dir("orientation_cli");
  test::write_obj(in.mesh, dir + "/mesh.obj");
  save_layout(displaced(in, 4, 1), dir + "/layout.json", &in.mesh);
  auto run = [&](const std::string& flags, const std::string& out) {
    std::string output;
    const int rc = test::run_command(test::cli_path() + " optimize --quiet --steps 0 --mesh " +
                                         dir + "/mesh.obj --layout " + dir + "/layout.json --out " +
                                         dir + "/" + out + " " + flags,
                                     &output);
    EXPECT_EQ(rc, 0) << output;
    std::ifstream f(dir + "/" + out + "/report.json");
    return nlohmann::json::parse(f);
  };
  const auto with = run("", "with"), without = run("--no-orientation", "without");
  const auto& n = with["node_optimization"];
  EXPECT_GT(n["foldovers_before_orientation"].get<int>(), 0);
  EXPECT_EQ(n["foldovers_final"].get<int>(), 0);
  EXPECT_EQ(n["fold_removal"], "orientation");
  EXPECT_TRUE(n["orientation"]["success"].get<bool>());
  EXPECT_EQ(with["metrics"]["foldovers"].get<int>(), 0) << "param.obj is the constrained solve";
  const double E_descent = n["E_descent"].get<double>(), E_final = with["E_final"].get<double>();
  EXPECT_GE(E_final, E_descent * (1 - 1e-9));
  EXPECT_LE(E_final, E_descent * 1.15);
  const auto& m = without["node_optimization"];
  EXPECT_FALSE(m["orientation"]["ran"].get<bool>());
  EXPECT_NE(m["fold_removal"], "orientation");
  EXPECT_EQ(m["foldovers_before_orientation"], n["foldovers_before_orientation"]);
}

TEST(OrientationNodeOpt, BundledExampleEndsWithoutFoldovers) {
  const std::string dir = test::assets_dir() + "/example";
  const TriMesh mesh = test::load_mesh(dir + "/ellipsoid.obj");
  const Layout layout = load_layout(dir + "/ellipsoid.layout.json", mesh);
  const NodeOptResult r = optimize_nodes(mesh, layout, PipelineOptions{});
  std::printf(
      "[stat] example: fold-overs init %d, before orientation %d, final %d; E %.6g -> %.6g\n",
      r.foldovers_init, r.foldovers_descent, r.foldovers_final, r.E_init, r.E_final);
  EXPECT_EQ(r.foldovers_final, 0);
  EXPECT_LE(r.E_final, r.E_init);
}

// Spot's quad mesh imported as a layout on its own triangulation, optimized: no fold-over
// remains and E is lowered.
TEST(OrientationRealData, SpotImportedOntoItselfEndsWithoutFoldovers) {
  const std::string dir = test::shared_meshes_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/data/meshes not found; real meshes skipped";
  const QuadImportResult imp =
      import_quads(test::load_poly_mesh(dir + "/spot/spot_quadrangulated.obj"), nullptr, {});
  const NodeOptResult r = optimize_nodes(imp.mesh, imp.layout, PipelineOptions{});
  std::printf(
      "[stat] spot: fold-overs init %d, before orientation %d, final %d (%s, %d faces, "
      "%d iterations, %.3f s); E %.6g -> %.6g -> %.6g\n",
      r.foldovers_init, r.foldovers_descent, r.foldovers_final,
      r.orientation_constraints ? "orientation" : "no constraints", r.orientation.constrained_faces,
      r.orientation.iterations, r.orientation.time_s, r.E_init, r.E_descent, r.E_final);
  EXPECT_EQ(r.foldovers_final, 0) << r.orientation.message;
  EXPECT_LT(r.E_final, r.E_init);
}

// Fandisk's quad mesh transferred onto fandisk.off (sharp features: iso-line constraints along
// them), without descent: the initial solve folds (11 faces when this was written); the
// constrained solve has none. (The full descent takes longer than a unit test should.)
TEST(OrientationRealData, FandiskInitialLayoutEndsWithoutFoldovers) {
  const std::string dir = test::shared_meshes_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/data/meshes not found; real meshes skipped";
  const TriMesh target = test::load_mesh(dir + "/fandisk/fandisk.off");
  const QuadImportResult imp =
      import_quads(test::load_poly_mesh(dir + "/fandisk/fandisk_quads.off"), &target, {});
  NodeOptOptions no;
  no.descent.max_steps = 0;
  const NodeOptResult r = optimize_nodes(imp.mesh, imp.layout, PipelineOptions{}, no);
  std::printf(
      "[stat] fandisk: fold-overs %d -> %d (%s, %d faces, %d iterations, %.3f s); "
      "E %.6g -> %.6g\n",
      r.foldovers_descent, r.foldovers_final,
      r.orientation_constraints ? "orientation" : "no constraints", r.orientation.constrained_faces,
      r.orientation.iterations, r.orientation.time_s, r.E_descent, r.E_final);
  EXPECT_GT(r.foldovers_descent, 0) << "the case should show fold-overs before";
  EXPECT_EQ(r.foldovers_final, 0) << r.orientation.message;
  EXPECT_LE(r.E_final, r.E_descent * 1.05);
}

// The faces an infeasible orientation solve on the mask names are where the iso-lines wrap
// around the free eye holes: each is nearer to an eye hole than to the outer boundary (in vertex
// rings), and the message names it.
void expect_named_faces_at_eye_holes(const TriMesh& mesh, const OrientationReport& report) {
  const std::vector<int>& named = report.infeasible_faces;
  ASSERT_FALSE(named.empty()) << report.message;
  EXPECT_LE(named.size(), 5u);
  std::vector<std::vector<int>> loops = boundary_loops(mesh);
  ASSERT_EQ(loops.size(), 3u);
  std::sort(loops.begin(), loops.end(),
            [](const auto& x, const auto& y) { return x.size() > y.size(); });
  std::vector<int> eyes = loops[1];
  eyes.insert(eyes.end(), loops[2].begin(), loops[2].end());
  const std::vector<int> to_eye = test::ring_distances(mesh, eyes),
                         to_outer = test::ring_distances(mesh, loops[0]);
  int nearer_eye = 0;  // of all faces, for scale
  for (auto f : mesh.faces())
    nearer_eye += test::face_ring_distance(mesh, to_eye, f.idx()) <
                  test::face_ring_distance(mesh, to_outer, f.idx());
  std::printf("[stat] mask: %d of %zu faces are nearer to an eye hole than to the outer boundary\n",
              nearer_eye, static_cast<size_t>(mesh.n_faces()));
  for (int f : named) {
    ASSERT_GE(f, 0);
    ASSERT_LT(f, static_cast<int>(mesh.n_faces()));
    const int eye = test::face_ring_distance(mesh, to_eye, f),
              outer = test::face_ring_distance(mesh, to_outer, f);
    std::printf(
        "[stat] mask: named face %d, %d rings from an eye hole, %d from the outer boundary\n", f,
        eye, outer);
    EXPECT_LT(eye, outer) << "face " << f;
    EXPECT_NE(report.message.find(std::to_string(f)), std::string::npos) << report.message;
  }
}

// mask_confmap.obj (three boundary loops) with one node and four dangling arcs to the eye
// holes and the outer boundary (as in boundary_test), with the field wrapping around the free
// eye holes (FreeLoopTurning::kWrap, the earlier default; the default now embeds this
// layout): the fold-overs where the iso-lines wrap around the holes cannot be removed by the
// tri-sector constraints (the QP is infeasible). The solve must say so and keep the
// unconstrained solution; the node optimizer then falls back to stiffening.
TEST(OrientationRealData, InfeasibleConstraintsOnMaskKeepTheSolveAndSayWhy) {
  const std::string dir = test::shared_meshes_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/data/meshes not found; real meshes skipped";
  const TriMesh mesh = test::load_mesh(dir + "/mask_confmap.obj");
  const test::MaskStar star = test::mask_star(mesh);
  ASSERT_EQ(star.boundary_loops, 3u);
  const Layout layout = test::dangling_star_layout(mesh, star.center, star.targets);
  for (const LayoutArc& arc : layout.arcs) ASSERT_GE(arc.path.size(), 2u);
  PipelineOptions options;
  options.field.constraints.curvature = false;
  options.field.free_loops = FreeLoopTurning::kWrap;
  Pipeline plain(mesh, layout, options);
  const Parameterization& a = plain.compute_parameterization();
  options.param.orientation.enabled = true;
  Pipeline oriented(mesh, layout, options);
  const Parameterization& b = oriented.compute_parameterization();
  std::printf("[stat] mask: fold-overs %d -> %d, %s\n", a.foldovers, b.foldovers,
              b.orientation.message.c_str());
  ASSERT_GT(a.foldovers, 0);
  EXPECT_TRUE(b.orientation.ran);
  if (b.orientation.success) {  // should the constraints ever become feasible here
    EXPECT_LT(b.foldovers, a.foldovers);
  } else {
    EXPECT_NE(b.orientation.message.find("infeasible"), std::string::npos) << b.orientation.message;
    EXPECT_EQ(b.foldovers, a.foldovers);
    EXPECT_EQ(b.energy, a.energy);
    expect_named_faces_at_eye_holes(mesh, b.orientation);
  }
}

// OrientationOptions::stop_if_all_faces_infeasible on the mask with wrapping eye holes (whose
// constraints are infeasible on every face): small sets around the folded faces first (rings 0),
// then every face; that round is infeasible, and the solve stops there with the best earlier round
// instead of growing the set further (the node optimizer's setting where it has an earlier state to
// fall back to).
TEST(OrientationRealData, StopsWhenEveryFaceIsInfeasible) {
  const std::string dir = test::shared_meshes_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/data/meshes not found; real meshes skipped";
  const TriMesh mesh = test::load_mesh(dir + "/mask_confmap.obj");
  const test::MaskStar star = test::mask_star(mesh);
  const Layout layout = test::dangling_star_layout(mesh, star.center, star.targets);
  PipelineOptions options;
  options.field.constraints.curvature = false;
  options.field.free_loops = FreeLoopTurning::kWrap;
  options.param.orientation.enabled = true;
  options.param.orientation.rings = 0;
  options.param.orientation.all_faces_after_rounds = 1;
  // The scenario needs the field frame's sectors: with the solution frame (the default) the
  // first round is already infeasible there.
  options.param.orientation.sector_frame = SectorFrame::kField;
  OrientationReport report[2];
  for (int stop = 0; stop < 2; ++stop) {
    options.param.orientation.stop_if_all_faces_infeasible = stop != 0;
    Pipeline p(mesh, layout, options);
    report[stop] = p.compute_parameterization().orientation;
    std::printf("[stat] mask, rings 0, stop %d: rounds %d, all faces %d, %d -> %d fold-overs, %s\n",
                stop, report[stop].rounds, report[stop].all_faces ? 1 : 0,
                report[stop].foldovers_before, report[stop].foldovers_after,
                report[stop].message.c_str());
  }
  ASSERT_TRUE(report[1].ran);
  EXPECT_TRUE(report[1].all_faces);
  EXPECT_NE(report[1].message.find("infeasible on every face"), std::string::npos)
      << report[1].message;
  EXPECT_LT(report[1].rounds, report[0].rounds);
  // Every face constrained: the named faces could be anywhere on the mask.
  expect_named_faces_at_eye_holes(mesh, report[1]);
  EXPECT_LE(report[1].foldovers_after, report[1].foldovers_before);
}

// OrientationOptions::stop_if_all_faces_infeasible, on three triangles P, Q, R whose shared
// unknown y1 must be positive for P and R and negative for Q: the unconstrained optimum folds P
// and R; a round on them alone (rings 0) unfolds them and folds Q; the all-faces round that
// follows (all_faces_after_rounds 1) is infeasible. With the option the solve stops there with
// the best earlier round (Q folded); without it, it goes back to growing rounds, which are
// infeasible too, one round later.
TEST(OrientationQp, StopsWhenEveryFaceIsInfeasible) {
  TriMesh mesh;
  for (int t = 0; t < 3; ++t) {
    const double x = 10.0 * t;
    mesh.add_vertex(Vec3(x, 0, 0));
    mesh.add_vertex(Vec3(x + 1, 0, 0));
    mesh.add_vertex(Vec3(x + 0.5, 0.8, 0));
    auto vh = [&](int k) { return mesh.vertex_handle(3 * t + k); };
    mesh.add_face(vh(0), vh(1), vh(2));
  }
  const GeometryCache geometry = build_geometry(mesh);
  const std::vector<double> theta{0.0, 0.0, 0.0};
  const std::vector<int> corner_wedge{0, 1, 2, 3, 4, 5, 6, 7, 8};
  // Wedge w holds (u, v) at x(2w), x(2w + 1). Triangle t: corners (10t, 0) and (10t + 1, 0)
  // fixed; apex P = (y0, y1), Q = (10 + y0, −y1), R = (20.5, y1).
  Reduction red;
  red.z0 = Eigen::VectorXd::Zero(18);
  red.Z.resize(18, 2);
  for (int t = 0; t < 3; ++t) {
    red.z0(6 * t) = 10.0 * t;
    red.z0(6 * t + 2) = 10.0 * t + 1;
  }
  red.Z.insert(4, 0) = 1.0;  // P
  red.Z.insert(5, 1) = 1.0;
  red.z0(10) = 10.0;  // Q
  red.Z.insert(10, 0) = 1.0;
  red.Z.insert(11, 1) = -1.0;
  red.z0(16) = 20.5;  // R
  red.Z.insert(17, 1) = 1.0;
  Eigen::SparseMatrix<double> A(2, 2);
  A.insert(0, 0) = 1.0;
  A.insert(1, 1) = 1.0;
  const Eigen::VectorXd b = Eigen::Vector2d(0.5, -1.0);  // folds P and R
  OrientationOptions o;
  o.rings = 0;
  o.all_faces_after_rounds = 1;
  o.sector_frame = SectorFrame::kField;  // the rounds of one frame (no second attempt)
  OrientationReport report[2];
  Eigen::VectorXd y[2];
  for (int stop = 0; stop < 2; ++stop) {
    o.stop_if_all_faces_infeasible = stop != 0;
    y[stop] = solve_oriented(mesh, geometry, theta, corner_wedge, red, A, b, b, o, &report[stop]);
    std::printf(
        "[stat] three triangles, stop %d: rounds %d, all faces %d, %d -> %d fold-overs, %s\n", stop,
        report[stop].rounds, report[stop].all_faces ? 1 : 0, report[stop].foldovers_before,
        report[stop].foldovers_after, report[stop].message.c_str());
  }
  for (int stop = 0; stop < 2; ++stop) {
    EXPECT_EQ(report[stop].foldovers_before, 2);
    EXPECT_EQ(report[stop].foldovers_after, 1) << "the best round: Q folded";
    EXPECT_GT(y[stop](1), 0.0) << "the first round's solution: P and R unfolded";
  }
  EXPECT_TRUE(report[1].all_faces);
  EXPECT_NE(report[1].message.find("infeasible on every face"), std::string::npos)
      << report[1].message;
  EXPECT_EQ(report[1].rounds, 2);
  EXPECT_LT(report[1].rounds, report[0].rounds);
  EXPECT_NE(report[0].message.find("kept the best earlier round"), std::string::npos)
      << report[0].message;
  for (int f : report[1].infeasible_faces) {
    EXPECT_TRUE(f >= 0 && f < 3) << f;
    EXPECT_NE(report[1].message.find(std::to_string(f)), std::string::npos);
  }
  EXPECT_FALSE(report[1].infeasible_faces.empty());
}

}  // namespace
}  // namespace qs
