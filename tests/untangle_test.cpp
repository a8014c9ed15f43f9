// untangle (core/param/untangle.h): a folded map with exact equality constraints becomes
// fold-free while the constraints stay satisfied; a fold-free start is returned unchanged.
#include "core/param/untangle.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "core/base/errors.h"
#include "core/mesh/geometry.h"
#include "core/param/orientation.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

// A flat n × n grid; one wedge per vertex; the boundary vertices are fixed at their positions
// (z0), the interior ones free (y). A and b: the Dirichlet energy, minimal at the identity.
struct GridProblem {
  TriMesh mesh;
  GeometryCache geometry;
  std::vector<int> corner_wedge;
  Reduction reduction;
  Eigen::SparseMatrix<double> A;
  Eigen::VectorXd b;
  std::vector<int> interior;  // vertex of each free pair (u, v): y(2i), y(2i + 1)
};

GridProblem grid_problem(int n) {
  GridProblem p;
  p.mesh = test::disk_grid(n, n, 1, 1).mesh;
  p.geometry = build_geometry(p.mesh);
  const int nv = static_cast<int>(p.mesh.n_vertices());
  for (const auto fh : p.mesh.faces())
    for (const auto vh : p.mesh.fv_range(fh)) p.corner_wedge.push_back(vh.idx());
  std::vector<int> free_of(nv, -1);
  for (const auto vh : p.mesh.vertices()) {
    if (p.mesh.is_boundary(vh)) continue;
    free_of[vh.idx()] = static_cast<int>(p.interior.size());
    p.interior.push_back(vh.idx());
  }
  const int nfree = 2 * static_cast<int>(p.interior.size());
  Reduction& r = p.reduction;
  r.Z.resize(2 * nv, nfree);
  r.z0 = Eigen::VectorXd::Zero(2 * nv);
  std::vector<Eigen::Triplet<double>> z;
  for (const auto vh : p.mesh.vertices()) {
    const int i = vh.idx();
    if (free_of[i] >= 0) {
      z.emplace_back(2 * i, 2 * free_of[i], 1.0);
      z.emplace_back(2 * i + 1, 2 * free_of[i] + 1, 1.0);
    } else {
      r.z0(2 * i) = p.mesh.point(vh)[0];
      r.z0(2 * i + 1) = p.mesh.point(vh)[1];
    }
  }
  r.Z.setFromTriplets(z.begin(), z.end());
  // H: Σ_t a_t Gᵀ G for u and for v, in the 2·#V variables.
  std::vector<Eigen::Triplet<double>> h;
  for (int f = 0; f < p.geometry.n_faces; ++f) {
    const auto& gr = p.geometry.face_gradient[f];
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l) {
        const double v = gr[6] * (gr[2 * k] * gr[2 * l] + gr[2 * k + 1] * gr[2 * l + 1]);
        const int wk = p.corner_wedge[3 * f + k], wl = p.corner_wedge[3 * f + l];
        h.emplace_back(2 * wk, 2 * wl, v);
        h.emplace_back(2 * wk + 1, 2 * wl + 1, v);
      }
  }
  Eigen::SparseMatrix<double> H(2 * nv, 2 * nv);
  H.setFromTriplets(h.begin(), h.end());
  p.A = r.Z.transpose() * H * r.Z;
  p.b = -(r.Z.transpose() * (H * r.z0));
  return p;
}

Eigen::VectorXd identity_y(const GridProblem& p) {
  Eigen::VectorXd y(2 * p.interior.size());
  for (size_t i = 0; i < p.interior.size(); ++i) {
    const Vec3 x = p.mesh.point(p.mesh.vertex_handle(p.interior[i]));
    y(2 * i) = x[0];
    y(2 * i + 1) = x[1];
  }
  return y;
}

TEST(Untangle, FoldedGridWithFixedBoundaryUnfolds) {
  const GridProblem p = grid_problem(8);
  // The identity is the minimizer of q and fold-free.
  const Eigen::VectorXd y_id = identity_y(p);
  EXPECT_LT((p.A * y_id - p.b).norm(), 1e-9);
  EXPECT_EQ(count_foldovers(p.corner_wedge, p.reduction.Z * y_id + p.reduction.z0), 0);
  // Fold it: the interior's left half mirrored across the middle, and one vertex thrown far
  // outside the square.
  Eigen::VectorXd y = y_id;
  for (size_t i = 0; i < p.interior.size(); ++i)
    if (y(2 * i) < 4) y(2 * i) = 8 - y(2 * i) + 0.3;
  y(0) = -5;
  y(1) = 11;
  const int folds_before = count_foldovers(p.corner_wedge, p.reduction.Z * y + p.reduction.z0);
  ASSERT_GT(folds_before, 10);

  UntangleReport rep;
  const Eigen::VectorXd out =
      untangle(p.geometry, p.corner_wedge, p.reduction, p.A, p.b, y, UntangleOptions{}, &rep);
  std::printf("[stat] untangle: %d -> %d fold-overs, %d Newton steps, %d rounds, eps %.3g\n",
              rep.foldovers_before, rep.foldovers_after, rep.newton_steps, rep.rounds, rep.epsilon);
  EXPECT_TRUE(rep.ran);
  EXPECT_EQ(rep.foldovers_before, folds_before);
  EXPECT_EQ(rep.foldovers_after, 0);
  EXPECT_GT(rep.newton_steps, 0);
  const Eigen::VectorXd x = p.reduction.Z * out + p.reduction.z0;
  EXPECT_EQ(count_foldovers(p.corner_wedge, x), 0);
  // The constraints (the fixed boundary) hold exactly; every vertex stays in the square.
  for (const auto vh : p.mesh.vertices()) {
    const int i = vh.idx();
    if (p.mesh.is_boundary(vh)) {
      EXPECT_EQ(x(2 * i), p.mesh.point(vh)[0]);
      EXPECT_EQ(x(2 * i + 1), p.mesh.point(vh)[1]);
    } else {
      EXPECT_GT(x(2 * i), 0);
      EXPECT_LT(x(2 * i), 8);
      EXPECT_GT(x(2 * i + 1), 0);
      EXPECT_LT(x(2 * i + 1), 8);
    }
  }
}

// The faces' terms are split in two halves that sum separately whether or not the second half
// runs on another thread, so both settings give the same iterates, bit for bit.
TEST(Untangle, SecondThreadGivesTheSameMap) {
  const int n = 64;  // 8192 faces: the size from which the second thread is used
  const GridProblem p = grid_problem(n);
  ASSERT_GE(p.geometry.n_faces, 8000);
  Eigen::VectorXd y = identity_y(p);
  for (size_t i = 0; i < p.interior.size(); ++i)
    if (y(2 * i) < n / 2) y(2 * i) = n - y(2 * i) + 0.3;
  ASSERT_GT(count_foldovers(p.corner_wedge, p.reduction.Z * y + p.reduction.z0), 100);
  UntangleOptions one, two;
  one.second_thread = false;
  two.second_thread = true;
  UntangleReport rep_one, rep_two;
  const Eigen::VectorXd a =
      untangle(p.geometry, p.corner_wedge, p.reduction, p.A, p.b, y, one, &rep_one);
  const Eigen::VectorXd b =
      untangle(p.geometry, p.corner_wedge, p.reduction, p.A, p.b, y, two, &rep_two);
  std::printf("[stat] untangle %d faces: %d -> %d fold-overs, %d Newton steps, %.3f s / %.3f s\n",
              p.geometry.n_faces, rep_one.foldovers_before, rep_one.foldovers_after,
              rep_one.newton_steps, rep_one.time_s, rep_two.time_s);
  EXPECT_EQ(rep_one.foldovers_after, 0);
  EXPECT_EQ(rep_one.newton_steps, rep_two.newton_steps);
  EXPECT_EQ(rep_one.foldovers_after, rep_two.foldovers_after);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ((a - b).cwiseAbs().maxCoeff(), 0.0);
}

TEST(Untangle, FoldFreeStartIsReturnedAsItIs) {
  const GridProblem p = grid_problem(5);
  Eigen::VectorXd y = identity_y(p);
  y(0) += 0.2;  // off the minimizer, still fold-free
  UntangleReport rep;
  const Eigen::VectorXd out =
      untangle(p.geometry, p.corner_wedge, p.reduction, p.A, p.b, y, UntangleOptions{}, &rep);
  EXPECT_EQ(rep.foldovers_before, 0);
  EXPECT_EQ(rep.newton_steps, 0);
  EXPECT_EQ((out - y).norm(), 0.0);
}

TEST(Untangle, RejectsInconsistentInput) {
  const GridProblem p = grid_problem(4);
  const Eigen::VectorXd y = identity_y(p);
  EXPECT_THROW(untangle(p.geometry, p.corner_wedge, p.reduction, p.A, p.b,
                        Eigen::VectorXd::Zero(y.size() + 1), UntangleOptions{}),
               InvalidInputError);
  UntangleOptions bad;
  bad.beta = 0;
  EXPECT_THROW(untangle(p.geometry, p.corner_wedge, p.reduction, p.A, p.b, y, bad),
               InvalidInputError);
}

}  // namespace
}  // namespace qs
