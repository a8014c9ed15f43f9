// Sparse symmetric positive definite solver (CHOLMOD supernodal LLᵀ) that reuses its symbolic
// analysis: analyze a pattern once, factorize many times with new values, solve many times.
#pragma once

#include <Eigen/Sparse>
#include <memory>
#include <string>
#include <vector>

namespace qs {

//! Timings of the last operations, in seconds.
struct SpdSolverStats {
  double analyze_s = 0, factorize_s = 0, solve_s = 0;
  int analyses = 0, factorizations = 0, solves = 0;
  int hinted_analyses = 0;  //!< analyses that used a given ordering (set_ordering_hint)
  //! Analyses whose given ordering was dropped for CHOLMOD's own (more than
  //! SpdSolver::kSuspiciousFillPerNonzero nonzeros of L per nonzero of A, and more than AMD's)
  int rejected_hints = 0;
  double factor_nonzeros = 0;  //!< nonzeros of L predicted by the last analysis
  //! factorizations that scattered A's values into the lower triangle of P·A·Pᵀ, laid out once
  //! per analysis (every one of a compressed matrix), instead of CHOLMOD's permuted transposes
  int scattered_factorizations = 0;
};

class SpdSolver {
 public:
  //! \p stage names the solve in error messages ("cross field", "parameterization", …).
  explicit SpdSolver(std::string stage = "linear solve");
  ~SpdSolver();
  //! A copy shares the analysis and the factorization (no CHOLMOD work): it solves with the same
  //! factor. The first analyze(), factorize() or copy_analysis_from() of either side gives that
  //! side its own state first (copy-on-write; factorize() on an unchanged pattern copies the
  //! symbolic analysis), so the other keeps its factorization. Copies share CHOLMOD's workspace:
  //! do not use them from different threads at the same time.
  SpdSolver(const SpdSolver&);
  SpdSolver& operator=(const SpdSolver&);
  SpdSolver(SpdSolver&&) noexcept;
  SpdSolver& operator=(SpdSolver&&) noexcept;

  //! \p full: the matrices this solver gets store both triangles (exactly symmetric values):
  //! CHOLMOD then reads the upper triangle, which saves one permuted transpose of A in every
  //! numeric factorization. Default false: only the lower triangle is read (the upper may be
  //! absent). Takes effect at the next analysis.
  void set_full_storage(bool full) { full_storage_ = full; }
  bool full_storage() const { return full_storage_; }

  //! Symbolic analysis of the pattern of \p A (symmetric; the lower triangle is used, or the
  //! upper one with set_full_storage).
  void analyze(const Eigen::SparseMatrix<double>& A);
  //! Starts the symbolic analysis of \p A's pattern on another thread and returns at once (a
  //! no-op when the last analysis was of this pattern), so the caller can fill A's values
  //! meanwhile: the analysis reads the pattern only. Until the next call of any other member
  //! (they wait for it), \p A must stay alive with its pattern (size, column starts, row
  //! indices) unchanged. Analysis errors surface at that next call. Uses the ordering hint like
  //! analyze().
  void begin_analysis(const Eigen::SparseMatrix<double>& A);
  //! Blocks until an analysis begun by begin_analysis has finished (its result and errors are
  //! kept for the next call); for callers that must release A early, e.g. on an exception.
  void wait_for_analysis() const noexcept;
  //! Numeric factorization. Analyzes first unless the last analysis was of exactly this
  //! sparsity pattern (same size, same column starts and row indices; checked in O(nnz)), so a
  //! solver handed on to a new system with an identical pattern keeps its analysis.
  //! \throw SolverError when A is not positive definite or not finite.
  void factorize(const Eigen::SparseMatrix<double>& A);
  //! Takes over \p other's symbolic analysis (CHOLMOD factor copied; its numeric values are
  //! overwritten by the next factorize()), so a second solver for a matrix with the same
  //! pattern needs no analysis of its own. Any factorization of this solver is dropped.
  //! \return false (and nothing changed) when \p other has no analysis of a compressed matrix.
  bool copy_analysis_from(const SpdSolver& other);
  //! When a copy shares this solver's state (copies share it until one side analyzes or
  //! factorizes), gives this one its own copy of the CHOLMOD factor, numeric values and
  //! factorized state included: afterwards the two can be used on different threads at the
  //! same time (a shared state's solves would share CHOLMOD's workspace).
  void unshare();
  //! True when the last analysis was of exactly the pattern of \p A (compressed storage).
  bool same_pattern(const Eigen::SparseMatrix<double>& A) const;
  //! Solves A x = b with the last factorization. \throw SolverError on non-finite results.
  Eigen::VectorXd solve(const Eigen::VectorXd& b);
  Eigen::MatrixXd solve(const Eigen::MatrixXd& B);

  bool factorized() const;
  const SpdSolverStats& stats() const { return stats_; }

  //! The fill-reducing ordering of the last analysis: entry k is the column eliminated k-th
  //! (CHOLMOD's permutation, size n). Empty before the first analysis.
  std::vector<int> ordering() const;
  //! The next analysis (of a pattern other than the analyzed one) uses \p ordering (a
  //! permutation of 0..n-1, as ordering() returns) instead of computing one with AMD/METIS,
  //! when its size matches the matrix; a good ordering of a similar pattern (e.g. mapped from
  //! the previous step's system) gives nearly the same fill at a fraction of the analysis cost.
  //! Used once; an empty vector or one that is not a permutation clears the hint.
  //! When the given ordering's L has more than this many nonzeros per nonzero of A, CHOLMOD's
  //! own ordering is computed too and the one with less fill kept. Good orderings of the
  //! parameterization systems stay well below this bound; a bad one exceeds it several times.
  static constexpr double kSuspiciousFillPerNonzero = 8.0;
  void set_ordering_hint(std::vector<int> ordering);

 private:
  //! Gives this solver its own state if a copy shares it (\p keep_analysis: copy the analysis).
  void detach(bool keep_analysis);

  struct Impl;
  struct AnalysisResult {
    double seconds = 0;
    bool hinted = false;
    bool rejected_hint = false;
    double factor_nonzeros = 0;
  };
  //! The symbolic analysis of \p A into \p impl (its state replaced); \p hint: the ordering to
  //! use (empty: CHOLMOD's). \throw SolverError when CHOLMOD fails.
  static AnalysisResult run_analysis(Impl& impl, const Eigen::SparseMatrix<double>& A, bool upper,
                                     std::vector<int> hint, const std::string& stage);
  //! Waits for an analysis begun by begin_analysis and counts it in the stats (rethrows its
  //! error); a no-op without one.
  void collect_analysis();
  void note_analysis(const AnalysisResult& result);
  std::shared_ptr<Impl> impl_;
  std::string stage_;
  SpdSolverStats stats_;
  std::vector<int> ordering_hint_;  //!< for the next analysis (set_ordering_hint)
  bool full_storage_ = false;       //!< set_full_storage
};

//! A fill-reducing ordering of the symmetric \p A (both triangles stored, as
//! ReducedAssembly::A) for SpdSolver::set_ordering_hint: AMD on the quotient graph in which
//! the unknowns with the same \p group (size n, values in [0, n); e.g. the u and v unknowns of
//! one parameterization wedge) form one node, expanded back with the unknowns of a group
//! consecutive (increasing index). The quotient graph is smaller than A's graph (about a quarter
//! of its edges for pairs), so the ordering costs less than CHOLMOD's AMD on A; when the
//! unknowns of a group have (nearly) the same pattern the fill is the same.
//! \return a permutation of 0..n−1 (entry k: the unknown eliminated k-th); empty when \p group
//! does not fit A or AMD fails.
std::vector<int> grouped_amd_ordering(const Eigen::SparseMatrix<double>& A,
                                      const std::vector<int>& group);

//! A nested-dissection ordering (METIS, through CHOLMOD) of the undirected graph with \p n
//! nodes whose neighbours of node v are adjacency[start[v] .. start[v + 1]) (both directions
//! listed, no self loops). For orderings of unknowns that live on a mesh's vertices, expanded
//! from the vertex graph's once instead of ordering every new matrix (ParamOptions::vertex_order).
//! \return a permutation of 0..n−1 (entry k: the node eliminated k-th); empty when \p start
//! does not fit or METIS fails.
std::vector<int> nested_dissection_ordering(int n, const std::vector<int>& start,
                                            const std::vector<int>& adjacency);

//! A solver with set_full_storage(true), for matrices that store both triangles.
inline SpdSolver full_storage_solver(std::string stage) {
  SpdSolver solver(std::move(stage));
  solver.set_full_storage(true);
  return solver;
}

}  // namespace qs
