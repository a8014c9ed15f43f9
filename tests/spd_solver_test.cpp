// SpdSolver: CHOLMOD wrapper with reused symbolic analysis (issue #3 item 5).
#include "core/base/spd_solver.h"

#include <gtest/gtest.h>

#include <Eigen/CholmodSupport>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <thread>
#include <vector>

#include "core/base/errors.h"

namespace qs {
namespace {

// Graph Laplacian of an n×n grid plus `shift` on the diagonal (SPD for shift > 0). `bump`
// adds extra weight to every third diagonal entry, so two matrices share the pattern but not
// the values.
Eigen::SparseMatrix<double> grid_matrix(int n, double shift, double bump = 0) {
  std::vector<Eigen::Triplet<double>> t;
  auto id = [n](int i, int j) { return i * n + j; };
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const int a = id(i, j);
      double diag = shift + (a % 3 == 0 ? bump : 0.0);
      for (const auto& [di, dj] : {std::pair{1, 0}, std::pair{0, 1}}) {
        if (i + di >= n || j + dj >= n) continue;
        const int b = id(i + di, j + dj);
        t.emplace_back(a, b, -1.0);
        t.emplace_back(b, a, -1.0);
        t.emplace_back(b, b, 1.0);
        diag += 1.0;
      }
      t.emplace_back(a, a, diag);
    }
  }
  Eigen::SparseMatrix<double> A(n * n, n * n);
  A.setFromTriplets(t.begin(), t.end());
  A.makeCompressed();
  return A;
}

Eigen::VectorXd random_vector(int size, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> dist(-1, 1);
  Eigen::VectorXd b(size);
  for (int k = 0; k < size; ++k) b[k] = dist(rng);
  return b;
}

double relative_residual(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& x,
                         const Eigen::VectorXd& b) {
  return (A * x - b).norm() / b.norm();
}

TEST(SpdSolver, SolvesAndReusesTheAnalysisForTheSamePattern) {
  const auto A = grid_matrix(20, 0.1);
  const auto A2 = grid_matrix(20, 0.1, 5.0);  // same pattern, other values
  const Eigen::VectorXd b = random_vector(static_cast<int>(A.rows()), 1);
  SpdSolver solver("test");
  solver.factorize(A);
  EXPECT_LT(relative_residual(A, solver.solve(b), b), 1e-10);
  solver.factorize(A2);
  EXPECT_LT(relative_residual(A2, solver.solve(b), b), 1e-10);
  EXPECT_EQ(solver.stats().analyses, 1);
  EXPECT_EQ(solver.stats().factorizations, 2);
  // A different pattern is analyzed again.
  const auto B = grid_matrix(21, 0.1);
  solver.factorize(B);
  EXPECT_EQ(solver.stats().analyses, 2);
  const Eigen::VectorXd c = random_vector(static_cast<int>(B.rows()), 2);
  EXPECT_LT(relative_residual(B, solver.solve(c), c), 1e-10);
}

TEST(SpdSolver, CopiedAnalysisGivesTheSameSolutionWithoutAnAnalysis) {
  const auto A = grid_matrix(25, 0.05);
  const auto A2 = grid_matrix(25, 0.05, 3.0);
  const Eigen::VectorXd b = random_vector(static_cast<int>(A.rows()), 3);
  SpdSolver first("first"), second("second"), reference("reference");
  first.factorize(A);
  ASSERT_TRUE(second.copy_analysis_from(first));
  EXPECT_TRUE(second.same_pattern(A2));
  EXPECT_FALSE(second.factorized());  // only the analysis was taken over
  second.factorize(A2);
  EXPECT_EQ(second.stats().analyses, 0);
  reference.factorize(A2);
  const Eigen::VectorXd x = second.solve(b);
  EXPECT_LT(relative_residual(A2, x, b), 1e-10);
  EXPECT_LT((x - reference.solve(b)).norm(), 1e-10 * x.norm());
  // The source keeps its own factorization of A.
  EXPECT_LT(relative_residual(A, first.solve(b), b), 1e-10);
}

// A copy shares the factorization until it factorizes another matrix of the same pattern: it
// then takes over the analysis only (no new analysis) and the original keeps its own factor.
TEST(SpdSolver, SharedCopyFactorizesWithTheAnalysisOnly) {
  const auto A = grid_matrix(25, 0.05);
  const auto A2 = grid_matrix(25, 0.05, 3.0);
  const Eigen::VectorXd b = random_vector(static_cast<int>(A.rows()), 5);
  SpdSolver original("original"), reference("reference");
  original.factorize(A);
  const Eigen::VectorXd expected = original.solve(b);
  SpdSolver copy = original;
  const int analyses = copy.stats().analyses;
  copy.factorize(A2);
  EXPECT_EQ(copy.stats().analyses, analyses);
  reference.factorize(A2);
  const Eigen::VectorXd x = copy.solve(b);
  EXPECT_EQ(x, reference.solve(b));  // same ordering and supernodes: the same factor
  EXPECT_LT(relative_residual(A2, x, b), 1e-10);
  EXPECT_EQ(original.solve(b), expected);
  // Again, now with its own factor: the values are replaced in place.
  copy.factorize(A);
  EXPECT_EQ(copy.solve(b), expected);
}

TEST(SpdSolver, CopyFromAnUnanalyzedSolverChangesNothing) {
  SpdSolver empty("empty"), target("target");
  EXPECT_FALSE(target.copy_analysis_from(empty));
  EXPECT_FALSE(target.copy_analysis_from(target));
  EXPECT_FALSE(target.factorized());
  EXPECT_THROW(target.solve(Eigen::VectorXd(Eigen::VectorXd::Ones(3))), SolverError);
}

TEST(SpdSolver, RejectsIndefiniteAndNonFiniteInput) {
  SpdSolver solver("test");
  auto A = grid_matrix(6, -3.0);  // shifted below zero: indefinite
  EXPECT_THROW(solver.factorize(A), SolverError);
  auto B = grid_matrix(6, 0.1);
  B.coeffRef(4, 4) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(solver.factorize(B), SolverError);
  auto C = grid_matrix(6, 0.1);
  solver.factorize(C);
  Eigen::VectorXd b = Eigen::VectorXd::Ones(C.rows());
  b[2] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(solver.solve(b), SolverError);
  Eigen::SparseMatrix<double> rect(3, 4);
  EXPECT_THROW(solver.analyze(rect), SolverError);
}

// Two grid Laplacians interleaved (unknown 2k: first copy at node k, 2k + 1: second copy),
// coupled at a few nodes, like the u and v unknowns of the parameterization's wedges.
Eigen::SparseMatrix<double> paired_grid(int n) {
  const Eigen::SparseMatrix<double> G = grid_matrix(n, 0.1);
  std::vector<Eigen::Triplet<double>> t;
  for (int k = 0; k < G.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(G, k); it; ++it) {
      t.emplace_back(2 * it.row(), 2 * it.col(), it.value());
      t.emplace_back(2 * it.row() + 1, 2 * it.col() + 1, 1.5 * it.value());
    }
  for (int k = 0; k + 1 < n * n; k += 7) {  // u_k — v_{k+1} couplings (weakly: stays SPD)
    t.emplace_back(2 * k, 2 * (k + 1) + 1, 0.05);
    t.emplace_back(2 * (k + 1) + 1, 2 * k, 0.05);
  }
  Eigen::SparseMatrix<double> A(2 * n * n, 2 * n * n);
  A.setFromTriplets(t.begin(), t.end());
  A.makeCompressed();
  return A;
}

TEST(SpdSolver, GroupedAmdOrderingIsUsedAndGivesTheSameSolution) {
  const int n = 24;
  const auto A = paired_grid(n);
  const int size = static_cast<int>(A.rows());
  std::vector<int> group(size);
  for (int k = 0; k < size; ++k) group[k] = k / 2;
  const std::vector<int> order = grouped_amd_ordering(A, group);
  ASSERT_EQ(order.size(), static_cast<size_t>(size));
  std::vector<int> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  for (int k = 0; k < size; ++k) ASSERT_EQ(sorted[k], k) << "not a permutation";
  // The unknowns of a group are consecutive, in increasing index.
  for (int k = 0; k < size; k += 2) {
    EXPECT_EQ(group[order[k]], group[order[k + 1]]) << "position " << k;
    EXPECT_LT(order[k], order[k + 1]);
  }
  // Not the identity: a fill-reducing ordering of a grid reorders it.
  EXPECT_FALSE(std::is_sorted(order.begin(), order.end()));
  const Eigen::VectorXd b = random_vector(size, 5);
  SpdSolver hinted("hinted"), reference("reference");
  hinted.set_ordering_hint(order);
  hinted.factorize(A);
  EXPECT_EQ(hinted.stats().hinted_analyses, 1);
  EXPECT_EQ(hinted.ordering().size(), order.size());
  reference.factorize(A);
  EXPECT_EQ(reference.stats().hinted_analyses, 0);
  const Eigen::VectorXd xh = hinted.solve(b), xr = reference.solve(b);
  EXPECT_LT(relative_residual(A, xh, b), 1e-10);
  EXPECT_LT((xh - xr).norm(), 1e-9 * xr.norm());
  // Groups that do not fit: no ordering.
  EXPECT_TRUE(grouped_amd_ordering(A, std::vector<int>(size - 1, 0)).empty());
  std::vector<int> bad = group;
  bad[3] = size;
  EXPECT_TRUE(grouped_amd_ordering(A, bad).empty());
  bad[3] = -1;
  EXPECT_TRUE(grouped_amd_ordering(A, bad).empty());
}

// An "arrow" matrix: unknown 0 couples every other one, the others only themselves (both
// triangles stored). Eliminated first, the hub fills L completely; eliminated last, L has the
// pattern of A's lower triangle.
Eigen::SparseMatrix<double> arrow(int n) {
  std::vector<Eigen::Triplet<double>> t;
  for (int k = 0; k < n; ++k) t.emplace_back(k, k, k == 0 ? double(n) : 2.0);
  for (int k = 1; k < n; ++k) t.emplace_back(k, 0, 0.5), t.emplace_back(0, k, 0.5);
  Eigen::SparseMatrix<double> A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  A.makeCompressed();
  return A;
}

// A given ordering whose fill is far beyond SpdSolver::kSuspiciousFillPerNonzero per nonzero of
// A (the hub first: n(n+1)/2 nonzeros of L for 3n−2 of A) is replaced by CHOLMOD's own, which
// finds the arrow's 2n−1; a good one (the hub last) is kept. Same solution either way.
TEST(SpdSolver, AnOrderingHintWithFarMoreFillIsReplaced) {
  const int n = 400;
  const auto A = arrow(n);
  const Eigen::VectorXd b = random_vector(n, 11);
  std::vector<int> hub_first(n), hub_last(n);
  for (int k = 0; k < n; ++k) hub_first[k] = k, hub_last[k] = (k + 1) % n;

  SpdSolver bad("bad hint");
  bad.set_ordering_hint(hub_first);
  bad.factorize(A);
  EXPECT_EQ(bad.stats().rejected_hints, 1);
  EXPECT_EQ(bad.stats().hinted_analyses, 0);
  EXPECT_LE(bad.stats().factor_nonzeros, 2.0 * n);
  EXPECT_NE(bad.ordering().front(), 0) << "the hub is not eliminated first";

  SpdSolver good("good hint");
  good.set_ordering_hint(hub_last);
  good.factorize(A);
  EXPECT_EQ(good.stats().rejected_hints, 0);
  EXPECT_EQ(good.stats().hinted_analyses, 1);
  EXPECT_EQ(good.ordering().back(), 0) << "the hub is eliminated last";
  EXPECT_LE(good.stats().factor_nonzeros, 2.0 * n);

  // Without the check the bad hint's fill would be complete.
  EXPECT_GT(0.5 * n * (n + 1), SpdSolver::kSuspiciousFillPerNonzero * A.nonZeros());
  const Eigen::VectorXd xb = bad.solve(b), xg = good.solve(b);
  EXPECT_LT(relative_residual(A, xb, b), 1e-10);
  EXPECT_LT((xb - xg).norm(), 1e-9 * xg.norm());
}

// nested_dissection_ordering: a permutation whose last nodes (the top-level separator) cut a
// grid graph in two; as a hint it gives the default ordering's solution. Input that does not
// describe a graph gives no ordering.
TEST(SpdSolver, NestedDissectionOrdersAGridGraph) {
  const int n = 40;
  const auto A = grid_matrix(n, 0.5);
  const int size = static_cast<int>(A.rows());
  std::vector<int> start(size + 1, 0), adjacency;
  for (int c = 0; c < size; ++c) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, c); it; ++it)
      if (it.row() != c) adjacency.push_back(static_cast<int>(it.row()));
    start[c + 1] = static_cast<int>(adjacency.size());
  }
  const std::vector<int> order = nested_dissection_ordering(size, start, adjacency);
  ASSERT_EQ(order.size(), static_cast<size_t>(size));
  std::vector<int> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  for (int k = 0; k < size; ++k) ASSERT_EQ(sorted[k], k) << "not a permutation";
  // Without the last 2n nodes of the order the grid falls apart: the first separator is
  // eliminated last.
  std::vector<char> removed(size, 0);
  for (int k = size - 2 * n; k < size; ++k) removed[order[k]] = 1;
  std::vector<int> component(size, -1);
  int components = 0;
  for (int v = 0; v < size; ++v) {
    if (removed[v] || component[v] >= 0) continue;
    std::vector<int> stack{v};
    component[v] = components;
    while (!stack.empty()) {
      const int u = stack.back();
      stack.pop_back();
      for (int q = start[u]; q < start[u + 1]; ++q) {
        const int w = adjacency[q];
        if (!removed[w] && component[w] < 0) component[w] = components, stack.push_back(w);
      }
    }
    ++components;
  }
  EXPECT_GE(components, 2);
  const Eigen::VectorXd b = random_vector(size, 9);
  SpdSolver hinted("hinted"), reference("reference");
  hinted.set_ordering_hint(order);
  hinted.factorize(A);
  EXPECT_EQ(hinted.stats().hinted_analyses, 1);
  reference.factorize(A);
  const Eigen::VectorXd xh = hinted.solve(b), xr = reference.solve(b);
  EXPECT_LT(relative_residual(A, xh, b), 1e-10);
  EXPECT_LT((xh - xr).norm(), 1e-9 * xr.norm());
  // Not a graph: no ordering.
  EXPECT_TRUE(nested_dissection_ordering(size, std::vector<int>(size, 0), adjacency).empty());
  std::vector<int> bad = adjacency;
  bad[5] = size;
  EXPECT_TRUE(nested_dissection_ordering(size, start, bad).empty());
  EXPECT_TRUE(nested_dissection_ordering(0, {0}, {}).empty());
}

// A copy shares the factorization until unshare(): then both solve on two threads at the same
// time (run under TSan in CI) with the original's results, and refactorizing one leaves the
// other's factorization alone.
TEST(SpdSolver, UnsharedCopySolvesConcurrently) {
  const auto A = grid_matrix(30, 0.05);
  const auto A2 = grid_matrix(30, 0.05, 4.0);
  const Eigen::VectorXd b = random_vector(static_cast<int>(A.rows()), 7);
  SpdSolver original("original");
  original.factorize(A);
  const Eigen::VectorXd expected = original.solve(b);
  SpdSolver copy = original;
  copy.unshare();
  EXPECT_TRUE(copy.factorized());
  EXPECT_TRUE(copy.same_pattern(A));
  Eigen::VectorXd x_copy;
  std::thread other([&]() {
    for (int k = 0; k < 20; ++k) x_copy = copy.solve(b);
  });
  Eigen::VectorXd x_original;
  for (int k = 0; k < 20; ++k) x_original = original.solve(b);
  other.join();
  EXPECT_EQ(x_original, expected);
  EXPECT_EQ(x_copy, expected);                 // the same factor, copied
  const int analyses = copy.stats().analyses;  // counters are copied too
  copy.factorize(A2);                          // no analysis: the copied one is reused
  EXPECT_EQ(copy.stats().analyses, analyses);
  EXPECT_LT(relative_residual(A2, copy.solve(b), b), 1e-10);
  EXPECT_EQ(original.solve(b), expected);
  // Unsharing an unshared or empty solver changes nothing.
  SpdSolver empty("empty");
  empty.unshare();
  EXPECT_FALSE(empty.factorized());
  original.unshare();
  EXPECT_EQ(original.solve(b), expected);
}

// begin_analysis: the analysis of A's pattern runs on another thread while the caller writes A's
// values (it reads the pattern only); the factorization then needs no analysis of its own and
// solves exactly as a synchronous analysis would. Run under TSan in CI.
TEST(SpdSolver, BackgroundAnalysisWhileTheValuesAreWritten) {
  const auto target = grid_matrix(40, 0.05, 2.0);
  const Eigen::VectorXd b = random_vector(static_cast<int>(target.rows()), 11);
  Eigen::SparseMatrix<double> A = target;
  std::fill(A.valuePtr(), A.valuePtr() + A.nonZeros(), 0.0);  // values come later
  SpdSolver background("background");
  background.begin_analysis(A);
  for (Eigen::Index k = 0; k < A.nonZeros(); ++k) A.valuePtr()[k] = target.valuePtr()[k];
  background.factorize(A);
  EXPECT_EQ(background.stats().analyses, 1);
  EXPECT_EQ(background.stats().factorizations, 1);
  SpdSolver reference("reference");
  reference.factorize(target);
  EXPECT_EQ(background.ordering(), reference.ordering());
  const Eigen::VectorXd x = background.solve(b);
  EXPECT_LT(relative_residual(target, x, b), 1e-10);
  EXPECT_EQ(x, reference.solve(b));  // the same analysis and factorization, bit for bit
  // The analyzed pattern again: nothing starts, nothing is counted.
  background.begin_analysis(A);
  background.factorize(A);
  EXPECT_EQ(background.stats().analyses, 1);
  // Another pattern: counted once collected, with the full-storage setting of the solver.
  const auto B = grid_matrix(41, 0.05);
  background.set_full_storage(true);
  background.begin_analysis(B);
  EXPECT_TRUE(background.same_pattern(B));  // waits for the analysis
  background.factorize(B);
  EXPECT_EQ(background.stats().analyses, 2);
  const Eigen::VectorXd c = random_vector(static_cast<int>(B.rows()), 12);
  EXPECT_LT(relative_residual(B, background.solve(c), c), 1e-10);
  // Errors: a non-square matrix at once; a solver dropped or copied mid-analysis waits for it.
  EXPECT_THROW(background.begin_analysis(Eigen::SparseMatrix<double>(3, 4)), SolverError);
  {
    SpdSolver dropped("dropped");
    dropped.begin_analysis(B);
  }
  SpdSolver source("source");
  source.begin_analysis(B);
  SpdSolver copy = source;
  copy.wait_for_analysis();
  EXPECT_TRUE(copy.same_pattern(B));
  copy.factorize(B);
  EXPECT_LT(relative_residual(B, copy.solve(c), c), 1e-10);
  source.factorize(B);  // the source keeps its own analysis
  EXPECT_LT(relative_residual(B, source.solve(c), c), 1e-10);
}

// set_full_storage: the solver reads the upper triangle (else the lower one). A matrix whose
// strict lower triangle differs from its upper one tells which triangle was read.
TEST(SpdSolver, FullStorageReadsTheUpperTriangle) {
  const auto A = grid_matrix(12, 0.5);
  Eigen::SparseMatrix<double> skewed = A;  // lower triangle scaled: A's upper, another lower
  for (int k = 0; k < skewed.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(skewed, k); it; ++it)
      if (it.row() > it.col()) it.valueRef() *= 0.5;
  const Eigen::SparseMatrix<double> from_upper =
      Eigen::SparseMatrix<double>(skewed.selfadjointView<Eigen::Upper>());
  const Eigen::SparseMatrix<double> from_lower =
      Eigen::SparseMatrix<double>(skewed.selfadjointView<Eigen::Lower>());
  const Eigen::VectorXd b = random_vector(static_cast<int>(A.rows()), 3);
  SpdSolver full = full_storage_solver("full");
  EXPECT_TRUE(full.full_storage());
  full.factorize(skewed);
  EXPECT_LT(relative_residual(from_upper, full.solve(b), b), 1e-10);
  SpdSolver lower("lower");
  EXPECT_FALSE(lower.full_storage());
  lower.factorize(skewed);
  EXPECT_LT(relative_residual(from_lower, lower.solve(b), b), 1e-10);
  // Switching the storage re-analyzes (same pattern), and a copy keeps the setting.
  SpdSolver copy = full;
  EXPECT_TRUE(copy.full_storage());
  lower.set_full_storage(true);
  const int analyses = lower.stats().analyses;
  lower.factorize(skewed);
  EXPECT_EQ(lower.stats().analyses, analyses + 1);
  EXPECT_LT(relative_residual(from_upper, lower.solve(b), b), 1e-10);
  // On an exactly symmetric matrix both read the same system.
  full.factorize(A);
  SpdSolver plain("plain");
  plain.factorize(A);
  EXPECT_LT((full.solve(b) - plain.solve(b)).norm(), 1e-12 * plain.solve(b).norm());
}

// A factorization scatters A's values into the lower triangle of P·A·Pᵀ that the analysis laid
// out (both storage modes, analyzed here, on another thread, copied or with a given ordering)
// and solves exactly as CHOLMOD's own permuted factorization; an uncompressed matrix takes
// CHOLMOD's path. A matrix of the same pattern that is not positive definite is still refused.
TEST(SpdSolver, FactorizationsScatterIntoThePermutedLowerTriangle) {
  const auto A = paired_grid(9);
  const Eigen::VectorXd b = random_vector(static_cast<int>(A.rows()), 4);
  // Reference: Eigen's own CHOLMOD wrapper (cholmod_factorize with its permuted transposes).
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> reference(A);
  const Eigen::VectorXd x = reference.solve(b);
  auto check = [&](SpdSolver& solver, const char* what) {
    const int before = solver.stats().scattered_factorizations;
    solver.factorize(A);
    EXPECT_EQ(solver.stats().scattered_factorizations, before + 1) << what;
    EXPECT_LT((solver.solve(b) - x).norm(), 1e-12 * x.norm()) << what;
  };
  SpdSolver lower("lower");
  check(lower, "lower triangle");
  check(lower, "again, analysis reused");
  SpdSolver full = full_storage_solver("full");
  check(full, "upper triangle");
  SpdSolver background("background");
  background.begin_analysis(A);
  check(background, "analysis on another thread");
  SpdSolver copied("copied");
  ASSERT_TRUE(copied.copy_analysis_from(lower));
  check(copied, "copied analysis");
  SpdSolver shared = lower;
  check(shared, "copy-on-write");
  SpdSolver hinted("hinted");
  std::vector<int> group(A.rows());
  for (int k = 0; k < static_cast<int>(A.rows()); ++k) group[k] = k / 2;
  hinted.set_ordering_hint(grouped_amd_ordering(A, group));
  check(hinted, "given ordering");
  EXPECT_EQ(hinted.stats().hinted_analyses, 1);

  Eigen::SparseMatrix<double> loose = A;
  loose.uncompress();
  SpdSolver plain("uncompressed");
  plain.factorize(loose);
  EXPECT_EQ(plain.stats().scattered_factorizations, 0);
  EXPECT_LT((plain.solve(b) - x).norm(), 1e-12 * x.norm());

  Eigen::SparseMatrix<double> indefinite = A;
  for (int k = 0; k < indefinite.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(indefinite, k); it; ++it)
      if (it.row() == it.col() && it.row() == 37) it.valueRef() = -1.0;
  EXPECT_THROW(lower.factorize(indefinite), SolverError);
  EXPECT_FALSE(lower.factorized());
  check(lower, "after a refused matrix");
}

}  // namespace
}  // namespace qs
