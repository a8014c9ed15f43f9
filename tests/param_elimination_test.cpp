// Exact constraint elimination, reduced-matrix assembly and analysis reuse of the
// parameterization (issue #4): incompatible rows are reported with their origins (arc ids),
// redundant rows are dropped, x = Z·y + z0 parametrizes exactly the solution set, and
// A = ZᵀHZ from the fixed-pattern assembly equals the sparse triple product.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <random>

#include "core/base/errors.h"
#include "core/field/cross_field.h"
#include "core/layout/validate.h"
#include "core/param/constraints.h"
#include "core/param/parameterization.h"
#include "core/param/reduced_assembly.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

LinearRow row(std::vector<std::pair<int, double>> terms, double rhs, int origin) {
  LinearRow r;
  r.terms = std::move(terms);
  r.rhs = rhs;
  r.origin = origin;
  return r;
}

// Dense C and c of a system.
void dense_system(const ConstraintSystem& sys, Eigen::MatrixXd& C, Eigen::VectorXd& c) {
  C = Eigen::MatrixXd::Zero(static_cast<int>(sys.rows.size()), sys.variables);
  c.resize(static_cast<int>(sys.rows.size()));
  for (size_t i = 0; i < sys.rows.size(); ++i) {
    for (auto [v, a] : sys.rows[i].terms) C(i, v) += a;
    c(i) = sys.rows[i].rhs;
  }
}

TEST(Elimination, IncompatibleRowsNameTheirArcs) {
  ConstraintSystem sys;
  sys.variables = 4;
  const int a3 = sys.add_origin("arc 3 (node connection)");
  const int a5 = sys.add_origin("arc 5 (node connection)");
  const int a7 = sys.add_origin("arc 7 (node connection)");
  sys.rows.push_back(row({{0, 1.0}, {1, -1.0}}, 0.0, a3));
  sys.rows.push_back(row({{1, 1.0}, {2, -1.0}}, 0.0, a5));
  sys.rows.push_back(row({{0, 1.0}, {2, -1.0}}, 0.5, a7));  // contradicts the two above
  try {
    eliminate_constraints(sys);
    FAIL() << "incompatible constraints were accepted";
  } catch (const InfeasibleLayoutError& e) {  // an input error the node optimizer rejects
    const std::string what = e.what();
    EXPECT_NE(what.find("incompatible constraints (1)"), std::string::npos) << what;
    EXPECT_NE(what.find("arc 7"), std::string::npos) << what;
    EXPECT_EQ(what.find("arc 3"), std::string::npos) << what;
  }
}

TEST(Elimination, RedundantRowsAreDroppedNotSingular) {
  ConstraintSystem sys;
  sys.variables = 4;
  const int o = sys.add_origin("arc 1 (node connection)");
  sys.rows.push_back(row({{0, 1.0}, {1, -1.0}}, 1.0, o));
  sys.rows.push_back(row({{1, 1.0}, {2, -1.0}}, 2.0, o));
  sys.rows.push_back(row({{0, 1.0}, {2, -1.0}}, 3.0, o));  // the sum of the two above
  sys.rows.push_back(row({{0, 2.0}, {1, -2.0}}, 2.0, o));  // twice the first
  const Reduction red = eliminate_constraints(sys);
  EXPECT_EQ(red.redundant, 2);
  EXPECT_EQ(red.eliminated, 2);
  ASSERT_EQ(red.Z.cols(), 2);
  Eigen::MatrixXd C;
  Eigen::VectorXd c;
  dense_system(sys, C, c);
  const Eigen::MatrixXd Z = red.Z;
  EXPECT_LT((C * Z).norm(), 1e-14);
  EXPECT_LT((C * red.z0 - c).norm(), 1e-14);
  EXPECT_EQ(Eigen::FullPivLU<Eigen::MatrixXd>(Z).rank(), 2);
}

TEST(Elimination, BadVariableIsAnInputError) {
  ConstraintSystem sys;
  sys.variables = 2;
  sys.rows.push_back(row({{0, 1.0}, {5, -1.0}}, 0.0, sys.add_origin("arc 9 (node connection)")));
  EXPECT_THROW(eliminate_constraints(sys), InvalidInputError);
}

// Random sparse systems with ±1/±2 coefficients, consistent right-hand sides and some
// eliminate-last variables: Z spans exactly the null space of C and z0 solves the system.
TEST(Elimination, RandomSystemsAreReducedExactly) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 40; ++trial) {
    const int n = 10 + trial, rows = 3 + trial / 2 + static_cast<int>(rng() % 5);
    ConstraintSystem sys;
    sys.variables = n;
    sys.eliminate_last.assign(n, 0);
    for (int v = n - 1 - trial % 4; v < n; ++v) sys.eliminate_last[v] = 1;
    const int o = sys.add_origin("random row");
    Eigen::VectorXd x_true = Eigen::VectorXd::Random(n);
    for (int i = 0; i < rows; ++i) {
      LinearRow r;
      const int len = 2 + static_cast<int>(rng() % 3);
      for (int k = 0; k < len; ++k) {
        const double coef[4] = {1.0, -1.0, 2.0, -2.0};
        r.terms.push_back({static_cast<int>(rng() % n), coef[rng() % 4]});
      }
      if (i > 2 && rng() % 4 == 0) r.terms = sys.rows[rng() % i].terms;  // duplicates
      r.origin = o;
      for (auto [v, a] : r.terms) r.rhs += a * x_true(v);
      sys.rows.push_back(r);
    }
    const Reduction red = eliminate_constraints(sys);
    Eigen::MatrixXd C;
    Eigen::VectorXd c;
    dense_system(sys, C, c);
    const Eigen::MatrixXd Z = red.Z;
    const int rank = static_cast<int>(Eigen::FullPivLU<Eigen::MatrixXd>(C).rank());
    EXPECT_EQ(Z.cols(), n - rank) << "trial " << trial;
    EXPECT_EQ(red.redundant, rows - rank) << "trial " << trial;
    EXPECT_LT((C * Z).norm(), 1e-12) << "trial " << trial;
    EXPECT_LT((C * red.z0 - c).norm(), 1e-12 * (1 + c.norm())) << "trial " << trial;
    EXPECT_EQ(Eigen::FullPivLU<Eigen::MatrixXd>(Z).rank(), Z.cols()) << "trial " << trial;
    for (int v = 0; v < n; ++v)  // free variables are unit rows of Z
      if (red.free_index[v] >= 0) {
        EXPECT_EQ(Z(v, red.free_index[v]), 1.0);
      }
  }
}

// The fixed-pattern assembly equals Zᵀ·H·Z, with and without dense columns in Z.
TEST(ReducedAssembly, MatchesSparseTripleProduct) {
  std::mt19937 rng(3);
  const int wedges = 300, extra = 6, n = 2 * wedges + extra, nf = 500;
  std::vector<int> corner_wedge(3 * nf);
  for (int f = 0; f < nf; ++f) {
    const int a = static_cast<int>(rng() % (wedges - 2));
    corner_wedge[3 * f] = a, corner_wedge[3 * f + 1] = a + 1, corner_wedge[3 * f + 2] = a + 2;
  }
  for (int dense : {0, 3}) {
    // Z: unit rows for free variables; every 4th variable eliminated in terms of two others
    // and, with dense > 0, of `dense` columns used by most eliminated rows.
    std::vector<Eigen::Triplet<double>> t;
    std::vector<int> col(n, -1);
    int m = 0;
    for (int v = 0; v < n; ++v)
      if (v % 4 != 1) col[v] = m++;
    for (int v = 0; v < n; ++v) {
      if (col[v] >= 0) {
        t.emplace_back(v, col[v], 1.0);
        continue;
      }
      t.emplace_back(v, col[(v + 1) % n] >= 0 ? col[(v + 1) % n] : 0, 1.0);
      t.emplace_back(v, col[(v + 3) % n] >= 0 ? col[(v + 3) % n] : 2, -1.0);
      for (int k = 0; k < dense; ++k) t.emplace_back(v, m - 1 - k, k % 2 ? 0.5 : -1.0);
    }
    Eigen::SparseMatrix<double> Z(n, m);
    Z.setFromTriplets(t.begin(), t.end());
    ReducedAssembly ra(corner_wedge, wedges, n, Z);
    for (int round = 0; round < 2; ++round) {
      ra.clear();
      std::vector<Eigen::Triplet<double>> ht;
      for (int f = 0; f < nf; ++f) {
        Eigen::Matrix3d B = Eigen::Matrix3d::Random(), Hu = B * B.transpose();
        B = Eigen::Matrix3d::Random();
        const Eigen::Matrix3d Hv = B * B.transpose();
        ra.add_face(f, Hu, Hv);
        for (int k = 0; k < 3; ++k)
          for (int l = 0; l < 3; ++l) {
            ht.emplace_back(2 * corner_wedge[3 * f + k], 2 * corner_wedge[3 * f + l], Hu(k, l));
            ht.emplace_back(2 * corner_wedge[3 * f + k] + 1, 2 * corner_wedge[3 * f + l] + 1,
                            Hv(k, l));
          }
      }
      ra.reduce();
      Eigen::SparseMatrix<double> H(n, n);
      H.setFromTriplets(ht.begin(), ht.end());
      const Eigen::MatrixXd expected = Eigen::MatrixXd(Z.transpose() * H * Z);
      const Eigen::MatrixXd got = Eigen::MatrixXd(ra.A());
      EXPECT_LT((got - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff())
          << "dense columns " << dense << ", round " << round;
      EXPECT_LT((Eigen::MatrixXd(ra.H()) - Eigen::MatrixXd(H)).cwiseAbs().maxCoeff(), 1e-12);
    }
  }
}

// Large matrices: the pattern built from wedge_pattern() with A's columns in two halves on two
// threads is the one-thread pattern (same arrays), and A's values are ZᵀHZ's (sparse check).
TEST(ReducedAssembly, TwoThreadPatternIsTheOneThreadPattern) {
  std::mt19937 rng(5);
  const int wedges = 12000, extra = 8, n = 2 * wedges + extra, nf = 20000;
  std::vector<int> corner_wedge(3 * nf);
  for (int f = 0; f < nf; ++f) {
    const int a = static_cast<int>(rng() % (wedges - 40));
    corner_wedge[3 * f] = a, corner_wedge[3 * f + 1] = a + 1 + static_cast<int>(rng() % 19);
    corner_wedge[3 * f + 2] = a + 20 + static_cast<int>(rng() % 19);
  }
  std::vector<Eigen::Triplet<double>> t;
  std::vector<int> col(n, -1);
  int m = 0;
  for (int v = 0; v < n; ++v)
    if (v % 5 != 2) col[v] = m++;
  ASSERT_GE(m, 16384) << "the case must reach the two-thread size";
  for (int v = 0; v < n; ++v) {
    if (col[v] >= 0) {
      t.emplace_back(v, col[v], 1.0);
      continue;
    }
    t.emplace_back(v, col[(v + 1) % n], 1.0);
    t.emplace_back(v, col[(v + 4) % n], -1.0);
    if (v % 3 == 0)  // two dense columns used by a third of the eliminated rows
      for (int k = 0; k < 2; ++k) t.emplace_back(v, m - 1 - k, k ? 0.5 : -1.0);
  }
  Eigen::SparseMatrix<double> Z(n, m);
  Z.setFromTriplets(t.begin(), t.end());
  ReducedAssembly one(ReducedAssembly::wedge_pattern(corner_wedge, wedges), n, Z, false);
  ReducedAssembly two(ReducedAssembly::wedge_pattern(corner_wedge, wedges), n, Z, true);
  EXPECT_EQ(one.reduce_flops(), two.reduce_flops());
  std::vector<Eigen::Triplet<double>> ht;
  for (ReducedAssembly* ra : {&one, &two}) ra->clear();
  for (int f = 0; f < nf; ++f) {
    Eigen::Matrix3d B = Eigen::Matrix3d::Random();
    const Eigen::Matrix3d Hu = B * B.transpose();
    B = Eigen::Matrix3d::Random();
    const Eigen::Matrix3d Hv = B * B.transpose();
    for (ReducedAssembly* ra : {&one, &two}) ra->add_face(f, Hu, Hv);
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l) {
        ht.emplace_back(2 * corner_wedge[3 * f + k], 2 * corner_wedge[3 * f + l], Hu(k, l));
        ht.emplace_back(2 * corner_wedge[3 * f + k] + 1, 2 * corner_wedge[3 * f + l] + 1, Hv(k, l));
      }
  }
  one.reduce();
  two.reduce();
  const auto& A1 = one.A();
  const auto& A2 = two.A();
  ASSERT_EQ(A1.nonZeros(), A2.nonZeros());
  EXPECT_TRUE(std::equal(A1.outerIndexPtr(), A1.outerIndexPtr() + m + 1, A2.outerIndexPtr()));
  EXPECT_TRUE(
      std::equal(A1.innerIndexPtr(), A1.innerIndexPtr() + A1.nonZeros(), A2.innerIndexPtr()));
  EXPECT_TRUE(std::equal(A1.valuePtr(), A1.valuePtr() + A1.nonZeros(), A2.valuePtr()));
  Eigen::SparseMatrix<double> H(n, n);
  H.setFromTriplets(ht.begin(), ht.end());
  const Eigen::SparseMatrix<double> expected = Z.transpose() * H * Z;
  const Eigen::SparseMatrix<double> diff = A2 - expected;
  double max_diff = 0, max_expected = 0;
  for (int k = 0; k < diff.nonZeros(); ++k)
    max_diff = std::max(max_diff, std::abs(diff.valuePtr()[k]));
  for (int k = 0; k < expected.nonZeros(); ++k)
    max_expected = std::max(max_expected, std::abs(expected.valuePtr()[k]));
  EXPECT_GT(max_expected, 0.0);
  EXPECT_LT(max_diff, 1e-12 * max_expected);
}

// A second solver for the same combinatorics takes over the first one's CHOLMOD analysis and
// gives the same result; the reduced matrix is the exact ZᵀHZ of the solver's H.
TEST(ParamSolverReuse, SymbolicAnalysisIsReusedForIdenticalCombinatorics) {
  const auto in = test::cube_sphere(6);
  ASSERT_TRUE(validate_layout(in.mesh, in.layout).valid());
  const GeometryCache g = build_geometry(in.mesh);
  const LayoutTopology topo = build_topology(in.mesh, in.layout);
  const CrossField field = compute_cross_field(in.mesh, g, in.layout, topo);
  ParamSolver first(in.mesh, g, in.layout, topo, field.period_jump, field.theta);
  EXPECT_EQ(first.linear_solver().stats().analyses, 1);
  ParamSolver second(in.mesh, g, in.layout, topo, field.period_jump, field.theta, {}, &first);
  EXPECT_EQ(second.linear_solver().stats().analyses, 1) << "the analysis was redone";
  EXPECT_EQ(second.linear_solver().stats().factorizations, 2);
  const auto& a = first.result().corner_uv;
  const auto& b = second.result().corner_uv;
  ASSERT_EQ(a.size(), b.size());
  double worst = 0;
  for (size_t i = 0; i < a.size(); ++i)
    worst = std::max({worst, std::abs(a[i][0] - b[i][0]), std::abs(a[i][1] - b[i][1])});
  EXPECT_LT(worst, 1e-12);
  EXPECT_NEAR(first.result().energy, second.result().energy, 1e-12 * first.result().energy);
  // The first solver still works (it re-analyzes with the fresh linear solver it got).
  first.solve(in.mesh, g, field.theta);
  EXPECT_EQ(first.linear_solver().stats().analyses, 1);
  EXPECT_EQ(first.result().foldovers, second.result().foldovers);
}

}  // namespace
}  // namespace qs
