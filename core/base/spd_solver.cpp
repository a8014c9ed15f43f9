#include "core/base/spd_solver.h"

#include <Eigen/CholmodSupport>
#include <algorithm>
#include <chrono>
#include <vector>

#include "core/base/errors.h"
#include "core/base/timing.h"

namespace qs {

struct SpdSolver::Impl {
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> llt;
  Eigen::Index rows = -1;
  Eigen::Index nnz = -1;
  std::vector<int> outer, inner;  // pattern of the analyzed matrix (compressed)
  bool analyzed = false;
  bool factorized = false;
};

SpdSolver::SpdSolver(std::string stage)
    : impl_(std::make_unique<Impl>()), stage_(std::move(stage)) {}
SpdSolver::~SpdSolver() = default;
SpdSolver::SpdSolver(SpdSolver&&) noexcept = default;
SpdSolver& SpdSolver::operator=(SpdSolver&&) noexcept = default;

void SpdSolver::analyze(const Eigen::SparseMatrix<double>& A) {
  if (A.rows() != A.cols()) throw SolverError(stage_ + ": matrix is not square");
  const auto t0 = std::chrono::steady_clock::now();
  impl_->llt.analyzePattern(A);
  if (impl_->llt.info() != Eigen::Success)
    throw SolverError(stage_ + ": symbolic analysis failed (" + std::to_string(A.rows()) +
                      " unknowns)");
  impl_->rows = A.rows();
  impl_->nnz = A.nonZeros();
  if (A.isCompressed()) {
    impl_->outer.assign(A.outerIndexPtr(), A.outerIndexPtr() + A.outerSize() + 1);
    impl_->inner.assign(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
  } else {
    impl_->outer.clear();  // never matches: an uncompressed matrix is always re-analyzed
    impl_->inner.clear();
  }
  impl_->analyzed = true;
  impl_->factorized = false;
  stats_.analyze_s = seconds_since(t0);
  ++stats_.analyses;
}

void SpdSolver::factorize(const Eigen::SparseMatrix<double>& A) {
  if (!same_pattern(A)) analyze(A);
  for (Eigen::Index k = 0; k < A.nonZeros(); ++k) {
    if (!std::isfinite(A.valuePtr()[k]))
      throw SolverError(stage_ + ": matrix has non-finite entries (" + std::to_string(A.rows()) +
                        " unknowns)");
  }
  const auto t0 = std::chrono::steady_clock::now();
  impl_->llt.factorize(A);
  impl_->factorized = impl_->llt.info() == Eigen::Success;
  if (!impl_->factorized)
    throw SolverError(stage_ + ": matrix is not positive definite (" + std::to_string(A.rows()) +
                      " unknowns)");
  stats_.factorize_s = seconds_since(t0);
  ++stats_.factorizations;
}

Eigen::VectorXd SpdSolver::solve(const Eigen::VectorXd& b) {
  if (!impl_->factorized) throw SolverError(stage_ + ": solve called before a factorization");
  if (!b.allFinite()) throw SolverError(stage_ + ": right-hand side has non-finite entries");
  const auto t0 = std::chrono::steady_clock::now();
  Eigen::VectorXd x = impl_->llt.solve(b);
  stats_.solve_s = seconds_since(t0);
  ++stats_.solves;
  if (impl_->llt.info() != Eigen::Success || !x.allFinite())
    throw SolverError(stage_ + ": solve produced non-finite values (" + std::to_string(b.size()) +
                      " unknowns)");
  return x;
}

Eigen::MatrixXd SpdSolver::solve(const Eigen::MatrixXd& B) {
  if (!impl_->factorized) throw SolverError(stage_ + ": solve called before a factorization");
  if (!B.allFinite()) throw SolverError(stage_ + ": right-hand side has non-finite entries");
  const auto t0 = std::chrono::steady_clock::now();
  Eigen::MatrixXd X = impl_->llt.solve(B);
  stats_.solve_s = seconds_since(t0);
  ++stats_.solves;
  if (impl_->llt.info() != Eigen::Success || !X.allFinite())
    throw SolverError(stage_ + ": solve produced non-finite values");
  return X;
}

bool SpdSolver::same_pattern(const Eigen::SparseMatrix<double>& A) const {
  if (!impl_->analyzed || A.rows() != impl_->rows || A.cols() != impl_->rows ||
      A.nonZeros() != impl_->nnz || !A.isCompressed() ||
      impl_->outer.size() != static_cast<size_t>(A.outerSize()) + 1)
    return false;
  return std::equal(impl_->outer.begin(), impl_->outer.end(), A.outerIndexPtr()) &&
         std::equal(impl_->inner.begin(), impl_->inner.end(), A.innerIndexPtr());
}

bool SpdSolver::factorized() const {
  return impl_->factorized;
}

}  // namespace qs
