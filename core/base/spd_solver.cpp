#include "core/base/spd_solver.h"

#include <Eigen/CholmodSupport>
#include <algorithm>
#include <chrono>
#include <future>
#include <numeric>
#include <vector>

#include "core/base/errors.h"
#include "core/base/metis_signals.h"
#include "core/base/solver_threads.h"
#include "core/base/timing.h"

namespace qs {

namespace {

// The lower triangle of P·A·Pᵀ (P: the analysis' fill-reducing permutation, L->Perm) as
// CHOLMOD's supernodal numeric factorization reads it, with the place of each of A's stored
// values in it. cholmod_factorize forms this matrix with permuted transposes at every
// factorization (about 5 % of a field factorization on the 70K bunny, allocated anew each
// time); with the layout, made by the first factorization of an analysis, the others only
// scatter A's values.
struct PermutedLower {
  std::vector<int> col_start;  //!< size n + 1
  std::vector<int> row;        //!< per entry: row in P·A·Pᵀ (≥ its column), size nnz
  //! per stored value of A (compressed, column-major): its entry, or −1 when the factorization
  //! does not read it (the other triangle)
  std::vector<int> place;
};

std::shared_ptr<const PermutedLower> permuted_lower(const Eigen::SparseMatrix<double>& A,
                                                    bool upper, const int* perm) {
  if (!A.isCompressed() || perm == nullptr) return nullptr;
  const int n = static_cast<int>(A.rows());
  std::vector<int> position(n);  // inverse permutation: row r of A is row position[r] of P·A·Pᵀ
  for (int k = 0; k < n; ++k) position[perm[k]] = k;
  auto plan = std::make_shared<PermutedLower>();
  plan->col_start.assign(n + 1, 0);
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  auto read = [upper](int r, int c) { return upper ? r <= c : r >= c; };
  for (int c = 0; c < n; ++c)
    for (int q = outer[c]; q < outer[c + 1]; ++q)
      if (read(inner[q], c)) ++plan->col_start[std::min(position[inner[q]], position[c]) + 1];
  for (int c = 0; c < n; ++c) plan->col_start[c + 1] += plan->col_start[c];
  std::vector<int> next(plan->col_start.begin(), plan->col_start.end() - 1);
  plan->row.resize(plan->col_start[n]);
  plan->place.assign(A.nonZeros(), -1);
  for (int c = 0; c < n; ++c) {
    for (int q = outer[c]; q < outer[c + 1]; ++q) {
      if (!read(inner[q], c)) continue;
      const int a = position[inner[q]], b = position[c];
      const int at = next[std::min(a, b)]++;
      plan->row[at] = std::max(a, b);
      plan->place[q] = at;
    }
  }
  return plan;
}

// Eigen's supernodal LLᵀ with one addition: taking over another instance's symbolic analysis
// (ordering and supernodal structure) by copying its CHOLMOD factor, so a second solver for a
// matrix of the same pattern skips the fill-reducing ordering.
class SupernodalLlt
    : public Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> {
 public:
  // Failures are reported as SolverError by SpdSolver; CHOLMOD's own console messages off.
  SupernodalLlt() { cholmod().print = 0; }

  //! Takes over \p from's symbolic analysis (its numeric values are not copied: the next
  //! factorization computes them). \return false when \p from has no analysis or CHOLMOD could
  //! not copy it.
  bool copy_analysis_from(SupernodalLlt& from) {
    if (!from.m_analysisIsOk || from.m_cholmodFactor == nullptr) return false;
    cholmod_factor* copy = copy_symbolic(from.m_cholmodFactor, &cholmod());
    if (copy == nullptr) copy = cholmod_copy_factor(from.m_cholmodFactor, &cholmod());
    if (copy == nullptr) return false;
    adopt(copy);
    factor_nonzeros_ = from.factor_nonzeros_;
    return true;
  }
  //! Copy of \p from's whole factor (symbolic and numeric) and its factorized state.
  bool copy_factor_from(SupernodalLlt& from) {
    if (!from.m_analysisIsOk || from.m_cholmodFactor == nullptr) return false;
    cholmod_factor* copy = cholmod_copy_factor(from.m_cholmodFactor, &cholmod());
    if (copy == nullptr) return false;
    adopt(copy);
    factor_nonzeros_ = from.factor_nonzeros_;
    m_factorizationIsOk = from.m_factorizationIsOk;
    m_info = from.m_info;
    return true;
  }
  //! A symbolic supernodal factor with \p from's ordering and supernodal structure, as
  //! cholmod_analyze returns it, without \p from's numeric values (cholmod_copy_factor copies
  //! those too: on the 70K bunny's field a copy per factorization of a shared solver moved
  //! 12 MB). nullptr when \p from is not supernodal or memory runs out.
  static cholmod_factor* copy_symbolic(const cholmod_factor* from, cholmod_common* c) {
    if (!from->is_super || from->super == nullptr) return nullptr;
    const size_t n = from->n;
    cholmod_factor* f = cholmod_allocate_factor(n, c);
    if (f == nullptr) return nullptr;
    std::copy_n(static_cast<const int*>(from->Perm), n, static_cast<int*>(f->Perm));
    std::copy_n(static_cast<const int*>(from->ColCount), n, static_cast<int*>(f->ColCount));
    f->ordering = from->ordering;
    f->is_ll = from->is_ll;
    f->xsize = from->xsize;
    f->ssize = from->ssize;
    f->nsuper = from->nsuper;
    // Allocates super, pi, px (nsuper + 1 each) and s (ssize) of a symbolic supernodal factor.
    if (!cholmod_change_factor(CHOLMOD_PATTERN, /*to_ll=*/true, /*to_super=*/true,
                               /*to_packed=*/true, /*to_monotonic=*/true, f, c)) {
      cholmod_free_factor(&f, c);
      return nullptr;
    }
    const size_t ns = from->nsuper + 1;
    std::copy_n(static_cast<const int*>(from->super), ns, static_cast<int*>(f->super));
    std::copy_n(static_cast<const int*>(from->pi), ns, static_cast<int*>(f->pi));
    std::copy_n(static_cast<const int*>(from->px), ns, static_cast<int*>(f->px));
    std::copy_n(static_cast<const int*>(from->s), from->ssize, static_cast<int*>(f->s));
    f->maxcsize = from->maxcsize;
    f->maxesize = from->maxesize;
    f->minor = n;
    f->is_monotonic = from->is_monotonic;
    return f;
  }
  //! Makes \p factor (analysed, not factorized) this solver's.
  void adopt(cholmod_factor* factor) {
    if (m_cholmodFactor != nullptr) cholmod_free_factor(&m_cholmodFactor, &cholmod());
    m_cholmodFactor = factor;
    m_isInitialized = true;
    m_info = Eigen::Success;
    m_analysisIsOk = true;
    m_factorizationIsOk = false;
  }
  //! The view of \p A that CHOLMOD reads: its upper triangle (stype 1) when \p upper, else its
  //! lower triangle (stype −1).
  static cholmod_sparse view(const Eigen::SparseMatrix<double>& A, bool upper) {
    return upper ? Eigen::viewAsCholmod(A.selfadjointView<Eigen::Upper>())
                 : Eigen::viewAsCholmod(A.selfadjointView<Eigen::Lower>());
  }
  //! The same view without the values (an analysis reads the pattern only, so another thread
  //! may write A's values meanwhile: SpdSolver::begin_analysis).
  static cholmod_sparse pattern_view(const Eigen::SparseMatrix<double>& A, bool upper) {
    cholmod_sparse a = view(A, upper);
    a.xtype = CHOLMOD_PATTERN;
    a.x = nullptr;
    return a;
  }
  //! Symbolic analysis (AMD/METIS as CHOLMOD's defaults choose) of the triangle \p upper says.
  void analyze_triangle(const Eigen::SparseMatrix<double>& A, bool upper) {
    if (m_cholmodFactor != nullptr) cholmod_free_factor(&m_cholmodFactor, &cholmod());
    cholmod_sparse a = pattern_view(A, upper);
    const MetisSignalGuard guard;  // CHOLMOD's default may try METIS (metis_signals.h)
    m_cholmodFactor = cholmod_analyze(&a, &cholmod());
    factor_nonzeros_ = m_cholmodFactor != nullptr ? cholmod().lnz : 0;
    m_isInitialized = true;
    m_info = m_cholmodFactor != nullptr ? Eigen::Success : Eigen::NumericalIssue;
    m_analysisIsOk = m_cholmodFactor != nullptr;
    m_factorizationIsOk = false;
  }
  //! Numeric factorization of the triangle \p upper says. With the upper triangle CHOLMOD forms
  //! tril(PAPᵀ) with one permuted transpose; with the lower one it needs two.
  void factorize_triangle(const Eigen::SparseMatrix<double>& A, bool upper) {
    cholmod_sparse a = view(A, upper);
    double beta[2] = {0, 0};
    cholmod_factorize_p(&a, beta, nullptr, 0, m_cholmodFactor, &cholmod());
    m_info = m_cholmodFactor->minor == m_cholmodFactor->n ? Eigen::Success : Eigen::NumericalIssue;
    m_factorizationIsOk = true;
  }
  //! Numeric factorization of \p A with \p plan (permuted_lower of A's pattern and this
  //! analysis' permutation): A's values scattered into \p values (resized), then CHOLMOD's
  //! supernodal factorization of that matrix, without cholmod_factorize's permuted transposes.
  void factorize_permuted(const Eigen::SparseMatrix<double>& A, const PermutedLower& plan,
                          std::vector<double>& values) {
    values.resize(plan.row.size());
    const double* x = A.valuePtr();
    for (Eigen::Index q = 0; q < A.nonZeros(); ++q)
      if (plan.place[q] >= 0) values[plan.place[q]] = x[q];
    cholmod_sparse s{};
    s.nrow = s.ncol = static_cast<size_t>(A.rows());
    s.nzmax = plan.row.size();
    s.p = const_cast<int*>(plan.col_start.data());
    s.i = const_cast<int*>(plan.row.data());
    s.x = values.data();
    s.stype = -1;  // lower triangle, already permuted
    s.itype = CHOLMOD_INT;
    s.xtype = CHOLMOD_REAL;
    s.dtype = CHOLMOD_DOUBLE;
    s.sorted = 0;
    s.packed = 1;
    double beta[2] = {0, 0};
    const int ok = cholmod_super_numeric(&s, nullptr, beta, m_cholmodFactor, &cholmod());
    m_info =
        ok && m_cholmodFactor->minor == m_cholmodFactor->n ? Eigen::Success : Eigen::NumericalIssue;
    m_factorizationIsOk = true;
  }
  //! The fill-reducing permutation of the current analysis (L->Perm), or nullptr.
  const int* permutation() const {
    return m_analysisIsOk && m_cholmodFactor != nullptr && m_cholmodFactor->is_super
               ? static_cast<const int*>(m_cholmodFactor->Perm)
               : nullptr;
  }
  //! Symbolic analysis with the fill-reducing ordering \p perm (size n, perm[k] = the column
  //! eliminated k-th) instead of AMD/METIS; CHOLMOD still postorders its elimination tree.
  void analyze_with_ordering(const Eigen::SparseMatrix<double>& A, bool upper,
                             std::vector<int>& perm) {
    if (m_cholmodFactor != nullptr) cholmod_free_factor(&m_cholmodFactor, &cholmod());
    cholmod_sparse a = pattern_view(A, upper);
    cholmod_common& c = cholmod();
    const int nmethods = c.nmethods, ordering = c.method[0].ordering;
    c.nmethods = 1;
    c.method[0].ordering = CHOLMOD_GIVEN;
    m_cholmodFactor = cholmod_analyze_p(&a, perm.data(), nullptr, 0, &c);
    factor_nonzeros_ = m_cholmodFactor != nullptr ? c.lnz : 0;
    c.nmethods = nmethods;
    c.method[0].ordering = ordering;
    m_isInitialized = true;
    m_info = m_cholmodFactor != nullptr ? Eigen::Success : Eigen::NumericalIssue;
    m_analysisIsOk = m_cholmodFactor != nullptr;
    m_factorizationIsOk = false;
  }
  //! Nonzeros of L the current analysis predicts (CHOLMOD's lnz; 0 without one).
  double factor_nonzeros() const { return m_analysisIsOk ? factor_nonzeros_ : 0; }
  //! The ordering of the current analysis (empty without one).
  std::vector<int> ordering() const {
    if (!m_analysisIsOk || m_cholmodFactor == nullptr || m_cholmodFactor->Perm == nullptr)
      return {};
    const int* p = static_cast<const int*>(m_cholmodFactor->Perm);
    return std::vector<int>(p, p + m_cholmodFactor->n);
  }

 private:
  double factor_nonzeros_ = 0;
};

}  // namespace

struct SpdSolver::Impl {
  SupernodalLlt llt;
  Eigen::Index rows = -1;
  Eigen::Index nnz = -1;
  std::vector<int> outer, inner;  // pattern of the analyzed matrix (compressed)
  bool analyzed = false;
  bool factorized = false;
  bool upper = false;  // the analysis and factorizations read A's upper triangle
  // tril(P·A·Pᵀ) of the analyzed pattern (shared by copies with the same analysis) and the
  // values of the last factorization in it (each state its own).
  std::shared_ptr<const PermutedLower> permuted;
  std::vector<double> permuted_values;
  // An analysis running on another thread (begin_analysis). Declared last: destroying an Impl
  // first waits for it (std::async's future), before the factor it writes is freed.
  std::future<AnalysisResult> pending;

  //! The analyzed pattern's bookkeeping of \p from (size, pattern, triangle, P·A·Pᵀ layout),
  //! for a state that took over \p from's CHOLMOD factor; analyzed and factorized are the
  //! caller's to set.
  void take_pattern_of(const Impl& from) {
    rows = from.rows;
    nnz = from.nnz;
    outer = from.outer;
    inner = from.inner;
    upper = from.upper;
    permuted = from.permuted;
  }
  //! Waits for a pending analysis (without taking its result).
  void wait() const {
    if (pending.valid()) pending.wait();
  }
};

SpdSolver::AnalysisResult SpdSolver::run_analysis(Impl& impl, const Eigen::SparseMatrix<double>& A,
                                                  bool upper, std::vector<int> hint,
                                                  const std::string& stage) {
  const auto t0 = std::chrono::steady_clock::now();
  SpdSolver::AnalysisResult result;
  impl.analyzed = false;
  impl.factorized = false;
  impl.permuted.reset();
  if (static_cast<Eigen::Index>(hint.size()) == A.rows() && A.rows() > 0) {
    impl.llt.analyze_with_ordering(A, upper, hint);
    result.hinted = true;
    // A given ordering is cheaper than AMD's but can be far worse on a pattern it was not made
    // for. Where its fill is suspiciously large, CHOLMOD's own ordering is computed too and the
    // one with less fill kept (the given one analyzed again when it wins).
    const double hinted_fill = impl.llt.factor_nonzeros();
    if (impl.llt.info() == Eigen::Success &&
        hinted_fill > kSuspiciousFillPerNonzero * static_cast<double>(A.nonZeros())) {
      impl.llt.analyze_triangle(A, upper);
      if (impl.llt.info() == Eigen::Success && impl.llt.factor_nonzeros() < hinted_fill) {
        result.hinted = false;
        result.rejected_hint = true;
      } else {
        impl.llt.analyze_with_ordering(A, upper, hint);
      }
    }
  } else {
    impl.llt.analyze_triangle(A, upper);
  }
  if (impl.llt.info() != Eigen::Success)
    throw SolverError(stage + ": symbolic analysis failed (" + std::to_string(A.rows()) +
                      " unknowns)");
  impl.rows = A.rows();
  impl.nnz = A.nonZeros();
  if (A.isCompressed()) {
    impl.outer.assign(A.outerIndexPtr(), A.outerIndexPtr() + A.outerSize() + 1);
    impl.inner.assign(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
  } else {
    impl.outer.clear();  // never matches: an uncompressed matrix is always re-analyzed
    impl.inner.clear();
  }
  impl.analyzed = true;
  impl.upper = upper;
  result.factor_nonzeros = impl.llt.factor_nonzeros();
  result.seconds = seconds_since(t0);
  return result;
}

SpdSolver::SpdSolver(std::string stage)
    : impl_(std::make_shared<Impl>()), stage_(std::move(stage)) {}
SpdSolver::~SpdSolver() = default;
SpdSolver::SpdSolver(const SpdSolver&) = default;
SpdSolver& SpdSolver::operator=(const SpdSolver&) = default;
SpdSolver::SpdSolver(SpdSolver&&) noexcept = default;
SpdSolver& SpdSolver::operator=(SpdSolver&&) noexcept = default;

void SpdSolver::detach(bool keep_analysis) {
  if (impl_.use_count() <= 1) return;
  auto own = std::make_shared<Impl>();
  if (keep_analysis && impl_->analyzed && own->llt.copy_analysis_from(impl_->llt)) {
    own->take_pattern_of(*impl_);
    own->analyzed = true;
  }
  impl_ = std::move(own);
}

void SpdSolver::unshare() {
  collect_analysis();
  if (impl_.use_count() <= 1) return;
  auto own = std::make_shared<Impl>();
  if (impl_->analyzed && !own->llt.copy_factor_from(impl_->llt))
    throw SolverError(stage_ + ": could not copy the factorization");
  own->take_pattern_of(*impl_);
  own->analyzed = impl_->analyzed;
  own->factorized = impl_->factorized;
  impl_ = std::move(own);
}

void SpdSolver::analyze(const Eigen::SparseMatrix<double>& A) {
  collect_analysis();
  if (A.rows() != A.cols()) throw SolverError(stage_ + ": matrix is not square");
  limit_solver_threads_here();
  detach(false);
  std::vector<int> hint = std::move(ordering_hint_);
  ordering_hint_.clear();
  note_analysis(run_analysis(*impl_, A, full_storage_, std::move(hint), stage_));
}

void SpdSolver::begin_analysis(const Eigen::SparseMatrix<double>& A) {
  collect_analysis();
  if (A.rows() != A.cols()) throw SolverError(stage_ + ": matrix is not square");
  if (same_pattern(A) && impl_->upper == full_storage_) return;
  detach(false);
  std::vector<int> hint = std::move(ordering_hint_);
  ordering_hint_.clear();
  // impl_ stays alive and in place until the result is collected: every member that touches it
  // waits first, and an Impl's destruction waits for its pending analysis.
  Impl* impl = impl_.get();
  impl->analyzed = false;
  impl->factorized = false;
  impl->pending = std::async(std::launch::async, [impl, &A, upper = full_storage_,
                                                  hint = std::move(hint), stage = stage_]() {
    limit_solver_threads_here();
    return run_analysis(*impl, A, upper, hint, stage);
  });
}

void SpdSolver::wait_for_analysis() const noexcept {
  impl_->wait();
}

void SpdSolver::collect_analysis() {
  if (!impl_->pending.valid()) return;
  std::future<AnalysisResult> pending = std::move(impl_->pending);
  note_analysis(pending.get());  // rethrows the analysis' SolverError
}

void SpdSolver::note_analysis(const AnalysisResult& result) {
  stats_.analyze_s = result.seconds;
  ++stats_.analyses;
  stats_.hinted_analyses += result.hinted;
  stats_.rejected_hints += result.rejected_hint;
  stats_.factor_nonzeros = result.factor_nonzeros;
}

void SpdSolver::factorize(const Eigen::SparseMatrix<double>& A) {
  collect_analysis();
  limit_solver_threads_here();  // CHOLMOD's OpenMP regions (solver_threads.h)
  if (!same_pattern(A) || impl_->upper != full_storage_)
    analyze(A);
  else
    detach(true);  // a copy keeps the shared factorization
  for (Eigen::Index k = 0; k < A.nonZeros(); ++k) {
    if (!std::isfinite(A.valuePtr()[k]))
      throw SolverError(stage_ + ": matrix has non-finite entries (" + std::to_string(A.rows()) +
                        " unknowns)");
  }
  const auto t0 = std::chrono::steady_clock::now();
  // The first factorization of an analysis lays out P·A·Pᵀ in place of CHOLMOD's transposes
  // (about their cost); copies of this state share the layout.
  if (!impl_->permuted) impl_->permuted = permuted_lower(A, impl_->upper, impl_->llt.permutation());
  if (impl_->permuted) {
    impl_->llt.factorize_permuted(A, *impl_->permuted, impl_->permuted_values);
    ++stats_.scattered_factorizations;
  } else {
    impl_->llt.factorize_triangle(A, impl_->upper);
  }
  impl_->factorized = impl_->llt.info() == Eigen::Success;
  if (!impl_->factorized)
    throw SolverError(stage_ + ": matrix is not positive definite (" + std::to_string(A.rows()) +
                      " unknowns)");
  stats_.factorize_s = seconds_since(t0);
  ++stats_.factorizations;
}

Eigen::VectorXd SpdSolver::solve(const Eigen::VectorXd& b) {
  collect_analysis();
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
  collect_analysis();
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

bool SpdSolver::copy_analysis_from(const SpdSolver& other) {
  collect_analysis();
  other.impl_->wait();
  if (this == &other || !other.impl_->analyzed || other.impl_->outer.empty()) return false;
  const auto t0 = std::chrono::steady_clock::now();
  detach(false);
  if (!impl_->llt.copy_analysis_from(other.impl_->llt)) return false;
  impl_->take_pattern_of(*other.impl_);
  impl_->analyzed = true;
  impl_->factorized = false;
  stats_.analyze_s = seconds_since(t0);
  return true;
}

bool SpdSolver::same_pattern(const Eigen::SparseMatrix<double>& A) const {
  impl_->wait();
  if (!impl_->analyzed || A.rows() != impl_->rows || A.cols() != impl_->rows ||
      A.nonZeros() != impl_->nnz || !A.isCompressed() ||
      impl_->outer.size() != static_cast<size_t>(A.outerSize()) + 1)
    return false;
  return std::equal(impl_->outer.begin(), impl_->outer.end(), A.outerIndexPtr()) &&
         std::equal(impl_->inner.begin(), impl_->inner.end(), A.innerIndexPtr());
}

bool SpdSolver::factorized() const {
  impl_->wait();
  return impl_->factorized;
}

std::vector<int> SpdSolver::ordering() const {
  impl_->wait();
  return impl_->analyzed ? impl_->llt.ordering() : std::vector<int>{};
}

void SpdSolver::set_ordering_hint(std::vector<int> ordering) {
  if (!ordering.empty()) {
    // A permutation of 0..n-1, else CHOLMOD would reject it: cleared.
    std::vector<char> seen(ordering.size(), 0);
    for (int k : ordering) {
      if (k < 0 || k >= static_cast<int>(ordering.size()) || seen[k]) {
        ordering.clear();
        break;
      }
      seen[k] = 1;
    }
  }
  ordering_hint_ = std::move(ordering);
}

namespace {

//! CHOLMOD's view of the symmetric pattern with \p n columns, rows \p row[start[c] ..
//! start[c + 1]) in column c, of which CHOLMOD reads the upper triangle (stype 1): entries
//! below the diagonal are ignored.
cholmod_sparse upper_pattern(int n, const std::vector<int>& start, const std::vector<int>& row) {
  cholmod_sparse a{};
  a.nrow = a.ncol = static_cast<size_t>(n);
  a.nzmax = row.size();
  a.p = const_cast<int*>(start.data());
  a.i = row.empty() ? nullptr : const_cast<int*>(row.data());
  a.stype = 1;
  a.itype = CHOLMOD_INT;
  a.xtype = CHOLMOD_PATTERN;
  a.dtype = CHOLMOD_DOUBLE;
  a.sorted = 0;
  a.packed = 1;
  return a;
}

}  // namespace

std::vector<int> nested_dissection_ordering(int n, const std::vector<int>& start,
                                            const std::vector<int>& adjacency) {
  if (n <= 0 || start.size() != static_cast<size_t>(n) + 1 || start[0] != 0 ||
      start[n] != static_cast<int>(adjacency.size()))
    return {};
  for (int v = 0; v < n; ++v)
    if (start[v + 1] < start[v]) return {};
  for (int w : adjacency)
    if (w < 0 || w >= n) return {};
  std::vector<int> perm(n);
  std::iota(perm.begin(), perm.end(), 0);
  if (adjacency.empty()) return perm;  // no edges: any order is free of fill
  cholmod_common c;
  cholmod_start(&c);
  c.print = 0;
  // The lower entries of the both-ways adjacency are ignored.
  cholmod_sparse G = upper_pattern(n, start, adjacency);
  const MetisSignalGuard guard;  // metis_signals.h
  const int ok = cholmod_metis(&G, nullptr, 0, /*postorder=*/0, perm.data(), &c);
  cholmod_finish(&c);
  if (!ok) return {};
  return perm;
}

std::vector<int> grouped_amd_ordering(const Eigen::SparseMatrix<double>& A,
                                      const std::vector<int>& group) {
  const int n = static_cast<int>(A.cols());
  if (A.rows() != A.cols() || static_cast<int>(group.size()) != n || n == 0) return {};
  int groups = 0;
  for (int g : group) {
    if (g < 0 || g >= n) return {};
    groups = std::max(groups, g + 1);
  }
  // Members of each group (CSR, increasing index).
  std::vector<int> member_start(groups + 1, 0), members(n);
  for (int g : group) ++member_start[g + 1];
  for (int g = 0; g < groups; ++g) member_start[g + 1] += member_start[g];
  {
    std::vector<int> next(member_start.begin(), member_start.end() - 1);
    for (int k = 0; k < n; ++k) members[next[group[k]]++] = k;
  }
  // Quotient graph, upper triangle (row < column), one entry per adjacent pair of groups.
  std::vector<int> qp(groups + 1, 0), qi;
  qi.reserve(static_cast<size_t>(A.nonZeros()) / 4 + groups);
  std::vector<int> mark(groups, -1);
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  const int* nnz = A.innerNonZeroPtr();  // null when compressed
  for (int g = 0; g < groups; ++g) {
    mark[g] = g;
    for (int q = member_start[g]; q < member_start[g + 1]; ++q) {
      const int k = members[q];
      const int end = nnz ? outer[k] + nnz[k] : outer[k + 1];
      for (int p = outer[k]; p < end; ++p) {
        const int h = group[inner[p]];
        if (h < g && mark[h] != g) {
          mark[h] = g;
          qi.push_back(h);
        }
      }
    }
    qp[g + 1] = static_cast<int>(qi.size());
  }
  cholmod_common c;
  cholmod_start(&c);
  c.print = 0;
  cholmod_sparse Q = upper_pattern(groups, qp, qi);
  std::vector<int> qperm(groups);
  const int ok = qi.empty() ? 1 : cholmod_amd(&Q, nullptr, 0, qperm.data(), &c);
  if (qi.empty()) std::iota(qperm.begin(), qperm.end(), 0);
  cholmod_finish(&c);
  if (!ok) return {};
  std::vector<int> perm;
  perm.reserve(n);
  for (int g : qperm)
    perm.insert(perm.end(), members.begin() + member_start[g],
                members.begin() + member_start[g + 1]);
  return perm;
}

}  // namespace qs
