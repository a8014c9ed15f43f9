// Curl-reducing sizing field (core/param/sizing.h, docs/design.md, "Sizing field") and its use in
// the parameterization, the node-gradient estimator and the command line.
#include "core/param/sizing.h"

#include <gtest/gtest.h>

#include <Eigen/Sparse>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>

#include "core/base/errors.h"
#include "core/field/cross_field.h"
#include "core/field/topology.h"
#include "core/mesh/geometry.h"
#include "core/nodeopt/gradient.h"
#include "core/param/parameterization.h"
#include "core/pipeline/pipeline.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

// Flat annulus sector r ∈ [r0, r1], φ ∈ [0, sweep] (nr × nt cells, alternating diagonals) in
// the plane z = 0; a full annulus when sweep = 2π.
TriMesh annulus(int nr, int nt, double r0, double r1, double sweep) {
  const bool closed = std::abs(sweep - 2 * M_PI) < 1e-12;
  const int columns = closed ? nt : nt + 1;
  TriMesh mesh;
  std::vector<TriMesh::VertexHandle> v;
  for (int i = 0; i <= nr; ++i)
    for (int j = 0; j < columns; ++j) {
      // Geometric spacing in r keeps the cells near-square (conformal grid).
      const double r = r0 * std::pow(r1 / r0, static_cast<double>(i) / nr);
      const double a = sweep * j / nt;
      v.push_back(mesh.add_vertex(Vec3(r * std::cos(a), r * std::sin(a), 0)));
    }
  auto at = [&](int i, int j) { return v[i * columns + (j % columns)]; };
  for (int i = 0; i < nr; ++i)
    for (int j = 0; j < nt; ++j) {
      if ((i + j) % 2 == 0) {
        mesh.add_face(at(i, j), at(i, j + 1), at(i + 1, j + 1));
        mesh.add_face(at(i, j), at(i + 1, j + 1), at(i + 1, j));
      } else {
        mesh.add_face(at(i, j), at(i, j + 1), at(i + 1, j));
        mesh.add_face(at(i, j + 1), at(i + 1, j + 1), at(i + 1, j));
      }
    }
  return mesh;
}

Vec3 centroid(const TriMesh& mesh, const GeometryCache& g, int f) {
  Vec3 c(0, 0, 0);
  for (int v : g.face_vertices[f]) c += mesh.point(mesh.vertex_handle(v));
  return c / 3.0;
}

// A field given by a 3D direction per face, with the principal matching as period jumps.
void field_from_directions(const TriMesh& mesh, const GeometryCache& g,
                           const std::function<Vec3(const Vec3&)>& direction,
                           std::vector<double>& theta, std::vector<int>& p) {
  theta.resize(g.n_faces);
  for (int f = 0; f < g.n_faces; ++f)
    theta[f] = g.angle_in_face(f, direction(centroid(mesh, g, f)));
  p = principal_matching(g, theta);
}

// Integrability residual of the per-face target field e^{s_t} w_t (w_t: the direction at angle
// theta[f] + offset) on a disk-like mesh: min_u Σ A_t ‖∇_t u − e^{s_t} w_t‖² over piecewise
// linear u, relative to Σ A_t e^{2 s_t}. 0 for the gradient field of a PL function.
double integrability_residual(const TriMesh& mesh, const GeometryCache& g,
                              const std::vector<double>& theta, double offset,
                              const std::vector<double>& log_scale) {
  const int n = g.n_vertices;
  std::vector<Eigen::Triplet<double>> trip;
  Eigen::VectorXd b = Eigen::VectorXd::Zero(n);
  std::vector<Eigen::Matrix<double, 2, 3>> G(g.n_faces);
  std::vector<Eigen::Vector2d> target(g.n_faces);
  double norm = 0;
  for (int f = 0; f < g.n_faces; ++f) {
    const auto p = face_corners_2d(mesh, g, f);
    const double a2 =
        (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0]);
    for (int k = 0; k < 3; ++k) {
      const auto& q = p[(k + 1) % 3];
      const auto& r = p[(k + 2) % 3];
      G[f].col(k) = Eigen::Vector2d(-(r[1] - q[1]), r[0] - q[0]) / a2;
    }
    const double scale = log_scale.empty() ? 1.0 : std::exp(log_scale[f]);
    target[f] = scale * Eigen::Vector2d(std::cos(theta[f] + offset), std::sin(theta[f] + offset));
    const double A = g.face_area[f];
    norm += A * scale * scale;
    const Eigen::Matrix3d M = A * G[f].transpose() * G[f];
    const Eigen::Vector3d rhs = A * G[f].transpose() * target[f];
    for (int k = 0; k < 3; ++k) {
      b(g.face_vertices[f][k]) += rhs(k);
      for (int l = 0; l < 3; ++l)
        trip.emplace_back(g.face_vertices[f][k], g.face_vertices[f][l], M(k, l));
    }
  }
  trip.emplace_back(0, 0, 1.0);  // pins the constant
  Eigen::SparseMatrix<double> L(n, n);
  L.setFromTriplets(trip.begin(), trip.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(L);
  const Eigen::VectorXd u = solver.solve(b);
  double residual = 0;
  for (int f = 0; f < g.n_faces; ++f) {
    const auto& fv = g.face_vertices[f];
    const Eigen::Vector2d grad = G[f] * Eigen::Vector3d(u(fv[0]), u(fv[1]), u(fv[2]));
    residual += g.face_area[f] * (grad - target[f]).squaredNorm();
  }
  return residual / norm;
}

// The radial field on an annulus: û = e_r, v̂ = e_φ. log(z) = log r + iφ is conformal with
// |∇ log r| = |∇φ| = 1/r, so e^{s} (û, v̂) is integrable exactly for s = −log r + c.
TEST(Sizing, RadialFieldOnAnnulusGivesMinusLogRadius) {
  for (const double sweep : {2 * M_PI, M_PI}) {
    double spread[2] = {0, 0};  // max − min of s + log r at two resolutions
    for (int level = 0; level < 2; ++level) {
      const int nr = level == 0 ? 12 : 24;
      const TriMesh mesh = annulus(nr, sweep > 4 ? 4 * nr : 2 * nr, 1.0, 4.0, sweep);
      const GeometryCache g = build_geometry(mesh);
      std::vector<double> theta;
      std::vector<int> p;
      field_from_directions(
          mesh, g, [](const Vec3& x) { return Vec3(x[0], x[1], 0); }, theta, p);
      SizingOptions opt;
      opt.clamp = 10;  // no clamping: compare with the analytic scale
      const SizingField s = compute_sizing(mesh, g, theta, p, opt);
      ASSERT_EQ(static_cast<int>(s.log_scale.size()), g.n_faces);
      EXPECT_EQ(s.clamped_faces, 0);
      EXPECT_EQ(s.excluded_faces, 0);  // no singularity in the annulus
      // Compare up to the constant: s_v + log r_v has the same value everywhere.
      double lo = 1e300, hi = -1e300;
      for (auto v : mesh.vertices()) {
        const double d = s.vertex_log_scale[v.idx()] + std::log(mesh.point(v).norm());
        lo = std::min(lo, d);
        hi = std::max(hi, d);
      }
      spread[level] = hi - lo;
      std::printf("sweep %g, %d rings: s + log r in [%g, %g]\n", sweep, nr, lo, hi);
      // Normalization: Σ A e^{2s} = Σ A.
      double a = 0, ae = 0;
      for (int f = 0; f < g.n_faces; ++f) {
        a += g.face_area[f];
        ae += g.face_area[f] * std::exp(2 * s.log_scale[f]);
      }
      EXPECT_NEAR(ae / a, 1.0, 1e-9);
      if (sweep > 4 || level == 0) continue;
      // On the half annulus (a disk: single-valued potentials) the sized field is a gradient
      // up to discretization: v̂ = e_φ is far from integrable alone, e^{s} e_φ = ∇φ is;
      // û = e_r = ∇r and e^{s} e_r = ∇ log r are both integrable.
      const double v_before = integrability_residual(mesh, g, theta, M_PI / 2, {});
      const double v_after = integrability_residual(mesh, g, theta, M_PI / 2, s.log_scale);
      const double u_after = integrability_residual(mesh, g, theta, 0.0, s.log_scale);
      EXPECT_GT(v_before, 0.05);
      EXPECT_LT(v_after, 0.01 * v_before) << v_before << " -> " << v_after;
      EXPECT_LT(u_after, 0.01 * v_before);
    }
    // s spans log 4 ≈ 1.39 across the annulus; the error is a few percent of that and shrinks
    // under refinement.
    EXPECT_LT(spread[1], 0.08) << "sweep " << sweep;
    EXPECT_LT(spread[1], 0.75 * spread[0]) << "sweep " << sweep;
  }
}

// An integrable field (constant on a flat disk, the boundary-aligned layout's field): s = 0.
TEST(Sizing, ConstantFieldOnFlatDiskNeedsNoScale) {
  const auto in = test::disk_grid(8, 6, 2, 2);
  PipelineOptions o;
  o.param.sizing.enabled = true;
  Pipeline p(in.mesh, in.layout, o);
  const CrossField& field = p.compute_field();
  const SizingField s = compute_sizing(p.mesh(), p.geometry(), field.theta, field.period_jump);
  for (double x : s.log_scale) EXPECT_NEAR(x, 0.0, 1e-9);
  const FieldCurl c = field_curl(p.mesh(), p.geometry(), field.theta, field.period_jump);
  for (int f = 0; f < p.geometry().n_faces; ++f) {
    EXPECT_NEAR(c.u[f], 0.0, 1e-9);
    EXPECT_NEAR(c.v[f], 0.0, 1e-9);
  }
  const Parameterization& r = p.compute_parameterization();
  ASSERT_EQ(static_cast<int>(r.sizing_log_scale.size()), p.geometry().n_faces);
  EXPECT_NEAR(r.energy, 0.0, 1e-12);  // the grid map is exactly the target
}

// (c) The residual E of the parameterization (sized targets, same total squared length) and
// the conformal distortion on the cube-on-sphere layout, with and without sizing.
TEST(Sizing, LowersTheResidualOnCubeSphere) {
  const auto in = test::cube_sphere(10);
  double E[2], confor[2];
  for (int on = 0; on < 2; ++on) {
    PipelineOptions o;
    o.param.sizing.enabled = on == 1;
    Pipeline p(in.mesh, in.layout, o);
    const Parameterization& r = p.compute_parameterization();
    EXPECT_EQ(r.sizing_log_scale.empty(), on == 0);
    E[on] = r.energy;
    confor[on] = p.metrics().E_confor;
    // E is the energy actually minimized: face_energies with the same log-scale agree.
    EXPECT_NEAR(unweighted_energy(p.mesh(), p.geometry(), p.field()->theta, r, o.param), r.energy,
                1e-9 * (1 + r.energy));
  }
  EXPECT_LT(E[1], E[0]);
  EXPECT_LT(confor[1], confor[0]);
}

// (d) The estimator with sizing (s frozen per face, like the field) matches central
// differences of the re-solved parameterization energy.
TEST(Sizing, EstimatorMatchesFrozenDifferencesWithSizing) {
  auto in = test::cube_sphere(8);
  const GeometryCache g0 = build_geometry(in.mesh);
  for (int n : {0, 3}) {  // push two nodes off their symmetric positions
    const int v = in.layout.nodes[n].vertex;
    Vec3 t1, t2;
    tangent_basis(vertex_normal(in.mesh, g0, v), t1, t2);
    in.mesh.set_point(in.mesh.vertex_handle(v), in.mesh.point(in.mesh.vertex_handle(v)) +
                                                    0.3 * g0.mean_edge_length * (t1 + 0.5 * t2));
  }
  const GeometryCache g = build_geometry(in.mesh);
  const LayoutTopology topo = build_topology(in.mesh, in.layout);
  const CrossField field = compute_cross_field(in.mesh, g, in.layout, topo);
  ParamOptions opt;
  opt.sizing.enabled = true;
  ParamSolver solver(in.mesh, g, in.layout, topo, field.period_jump, field.theta, opt);
  const Parameterization first = solver.result();
  ASSERT_EQ(static_cast<int>(first.sizing_log_scale.size()), g.n_faces);
  double smax = 0;
  for (double s : first.sizing_log_scale) smax = std::max(smax, std::abs(s));
  ASSERT_GT(smax, 0.01) << "the sizing must be non-trivial for this test to mean anything";
  // The frozen sizing for the re-solves.
  ParamOptions frozen = opt;
  frozen.sizing.frozen_log_scale = first.sizing_log_scale;
  ParamSolver fixed(in.mesh, g, in.layout, topo, field.period_jump, field.theta, frozen);
  EXPECT_NEAR(fixed.result().energy, first.energy, 1e-9 * first.energy);
  std::vector<int> verts;
  for (const auto& node : in.layout.nodes) verts.push_back(node.vertex);
  const auto est = estimate_node_gradients(in.mesh, g, field.theta, first, opt, verts);
  const auto est_unsized =
      estimate_node_gradients(in.mesh, g, field.theta, first.corner_uv, opt, verts);
  double gmax = 0;
  for (const auto& e : est) gmax = std::max(gmax, e.norm());
  const double eps = 1e-6 * g.mean_edge_length;
  int checked = 0;
  double worst = 0, unsized_gap = 0;
  for (size_t i = 0; i < verts.size(); ++i) {
    if (est[i].norm() < 1e-3 * gmax) continue;
    const int v = verts[i];
    const Vec3 fd = test::frozen_field_difference(
        in.mesh, g, field.theta, v, eps,
        [&](const TriMesh& m, const GeometryCache& g2, const std::vector<double>& theta2) {
          const Parameterization& r = fixed.solve(m, g2, theta2);
          return unweighted_energy(m, g2, theta2, r, frozen);
        });
    worst = std::max(worst, (fd - est[i]).norm() / est[i].norm());
    unsized_gap = std::max(unsized_gap, (fd - est_unsized[i]).norm() / est[i].norm());
    ++checked;
  }
  EXPECT_GE(checked, 4);
  EXPECT_LT(worst, 1e-4);
  // Leaving the scale out of the estimator is measurably wrong (the test can fail).
  EXPECT_GT(unsized_gap, 100 * worst);
}

// (e) The clamp always holds, and a tight clamp is active.
TEST(Sizing, ClampBoundsTheLogScale) {
  const auto in = test::cube_sphere(8, Vec3(1.0, 1.6, 0.7));
  Pipeline p(in.mesh, in.layout);
  const CrossField& field = p.compute_field();
  for (double clamp : {0.0, 0.02, 0.1, 2.0}) {
    for (bool exclude : {true, false}) {
      SizingOptions o;
      o.clamp = clamp;
      o.exclude_singular_faces = exclude;
      const SizingField s =
          compute_sizing(p.mesh(), p.geometry(), field.theta, field.period_jump, o);
      double smax = 0;
      for (double x : s.log_scale) smax = std::max(smax, std::abs(x));
      EXPECT_LE(smax, clamp) << "clamp " << clamp;
      if (clamp == 0.02) {
        EXPECT_GT(s.clamped_faces, 0);
      }
      if (!exclude) {
        EXPECT_EQ(s.excluded_faces, 0);
      }
    }
  }
}

TEST(Sizing, FactorizationReusedWhenOnlyTheFieldChanges) {
  const auto in = test::cube_sphere(6);
  Pipeline p(in.mesh, in.layout);
  const CrossField& field = p.compute_field();
  SizingSolver solver(p.mesh(), p.geometry());
  const SizingField a = solver.solve(p.mesh(), p.geometry(), field.theta, field.period_jump);
  EXPECT_TRUE(a.refactorized);
  std::vector<double> rotated = field.theta;
  for (double& t : rotated) t += 0.3;  // a global rotation: same s (g is rotation-invariant)
  const SizingField b = solver.solve(p.mesh(), p.geometry(), rotated, field.period_jump);
  EXPECT_FALSE(b.refactorized);
  EXPECT_EQ(solver.linear_solver().stats().factorizations, 1);
  for (size_t f = 0; f < a.log_scale.size(); ++f) EXPECT_NEAR(a.log_scale[f], b.log_scale[f], 1e-9);
  // Moved vertices: numeric refactorization, symbolic analysis kept.
  TriMesh moved = p.mesh();
  const auto vh = moved.vertex_handle(5);
  moved.set_point(vh, moved.point(vh) * 1.05);
  GeometryCache g2 = p.geometry();
  update_geometry(moved, g2);
  const SizingField c = solver.solve(moved, g2, field.theta, field.period_jump);
  EXPECT_TRUE(c.refactorized);
  EXPECT_EQ(solver.linear_solver().stats().factorizations, 2);
  EXPECT_EQ(solver.linear_solver().stats().analyses, 1);
}

TEST(Sizing, BadInputIsReported) {
  const auto in = test::cube_sphere(4);
  const GeometryCache g = build_geometry(in.mesh);
  std::vector<double> theta(g.n_faces, 0.0);
  std::vector<int> p(g.n_edges, 0);
  SizingOptions o;
  o.clamp = -1;
  EXPECT_THROW(SizingSolver(in.mesh, g, o), InvalidInputError);
  o.clamp = std::nan("");
  EXPECT_THROW(SizingSolver(in.mesh, g, o), InvalidInputError);
  SizingSolver solver(in.mesh, g);
  EXPECT_THROW(solver.solve(in.mesh, g, std::vector<double>(3, 0.0), p), InvalidInputError);
  EXPECT_THROW(solver.solve(in.mesh, g, theta, std::vector<int>(2, 0)), InvalidInputError);
  EXPECT_THROW(field_curl(in.mesh, g, theta, p, std::vector<double>(1, 0.0)), InvalidInputError);
  Pipeline pl(in.mesh, in.layout);
  const CrossField& field = pl.compute_field();
  PipelineOptions po;
  po.param.sizing.enabled = true;
  po.param.sizing.frozen_log_scale.assign(5, 0.0);
  Pipeline bad(in.mesh, in.layout, po);
  EXPECT_THROW(bad.compute_parameterization(), InvalidInputError);
  EXPECT_THROW(face_energies(in.mesh, g, field.theta,
                             std::vector<std::array<double, 2>>(3 * g.n_faces, {0.0, 0.0}), {},
                             std::vector<double>(2, 0.0)),
               InvalidInputError);
}

// (f) The command line switches sizing on and off and reports the choice.
TEST(SizingCli, FlagsReachTheReport) {
  namespace fs = std::filesystem;
  ASSERT_TRUE(fs::exists(test::cli_path())) << "quadsketch-cli not built: " << test::cli_path();
  const std::string mesh = test::assets_dir() + "/example/ellipsoid.obj";
  const std::string layout = test::assets_dir() + "/example/ellipsoid_exact.layout.json";
  double E[2] = {0, 0};
  for (int on = 0; on < 2; ++on) {
    const std::string out = test::temp_dir(on ? "sizing_on" : "sizing_off");
    std::string log;
    const int rc = test::run_command(test::cli_path() + " optimize --quiet --no-node-opt " +
                                         (on ? "--sizing" : "--no-sizing") + " --mesh " + mesh +
                                         " --layout " + layout + " --out " + out,
                                     &log);
    ASSERT_EQ(rc, 0) << log;
    std::ifstream in(out + "/report.json");
    const auto report = nlohmann::json::parse(in);
    ASSERT_TRUE(report["parameterization"].contains("sizing"));
    EXPECT_EQ(report["parameterization"]["sizing"].get<bool>(), on == 1);
    E[on] = report["E_final"].get<double>();
  }
  EXPECT_NE(E[0], E[1]);  // the option changed the solve
  std::string log;
  EXPECT_NE(test::run_command(test::cli_path() + " optimize --sizing --no-sizing --mesh " + mesh +
                                  " --layout " + layout + " --out " + test::temp_dir("both"),
                              &log),
            0);
}

}  // namespace
}  // namespace qs
