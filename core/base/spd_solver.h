// Sparse symmetric positive definite solver (CHOLMOD supernodal LLᵀ) that reuses its symbolic
// analysis: analyze a pattern once, factorize many times with new values, solve many times.
#pragma once

#include <Eigen/Sparse>
#include <memory>
#include <string>

namespace qs {

//! Timings of the last operations, in seconds.
struct SpdSolverStats {
  double analyze_s = 0, factorize_s = 0, solve_s = 0;
  int analyses = 0, factorizations = 0, solves = 0;
};

class SpdSolver {
 public:
  //! \p stage names the solve in error messages ("cross field", "parameterization", …).
  explicit SpdSolver(std::string stage = "linear solve");
  ~SpdSolver();
  SpdSolver(SpdSolver&&) noexcept;
  SpdSolver& operator=(SpdSolver&&) noexcept;

  //! Symbolic analysis of the pattern of \p A (symmetric; the lower triangle is used).
  void analyze(const Eigen::SparseMatrix<double>& A);
  //! Numeric factorization. Analyzes first unless the last analysis was of exactly this
  //! sparsity pattern (same size, same column starts and row indices; checked in O(nnz)), so a
  //! solver handed on to a new system with an identical pattern keeps its analysis.
  //! \throw SolverError when A is not positive definite or not finite.
  void factorize(const Eigen::SparseMatrix<double>& A);
  //! True when the last analysis was of exactly the pattern of \p A (compressed storage).
  bool same_pattern(const Eigen::SparseMatrix<double>& A) const;
  //! Solves A x = b with the last factorization. \throw SolverError on non-finite results.
  Eigen::VectorXd solve(const Eigen::VectorXd& b);
  Eigen::MatrixXd solve(const Eigen::MatrixXd& B);

  bool factorized() const;
  const SpdSolverStats& stats() const { return stats_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string stage_;
  SpdSolverStats stats_;
};

}  // namespace qs
