#include "core/param/orientation.h"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/base/errors.h"
#include "core/base/spd_solver.h"
#include "core/base/timing.h"

namespace qs {

namespace {

constexpr int kNamedFaces = 5;               // faces an infeasible round names (OrientationReport)
constexpr double kMaxSectorTurn = M_PI / 4;  // solution-frame sectors: turn from the field frame

using Vec2 = Eigen::Vector2d;

double cross2(const Vec2& a, const Vec2& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// Face adjacency across interior edges.
std::vector<std::vector<int>> face_neighbours(const GeometryCache& g) {
  std::vector<std::vector<int>> out(g.n_faces);
  for (int e = 0; e < g.n_edges; ++e) {
    const int i = g.edge_face_i[e], j = g.edge_face_j[e];
    if (i < 0 || j < 0) continue;
    out[i].push_back(j);
    out[j].push_back(i);
  }
  return out;
}

// Adds `rings` rings of neighbours around the flagged faces (in place).
void grow(const std::vector<std::vector<int>>& nbr, int rings, std::vector<char>& in) {
  std::vector<int> front;
  for (int f = 0; f < static_cast<int>(in.size()); ++f)
    if (in[f]) front.push_back(f);
  for (int r = 0; r < rings; ++r) {
    std::vector<int> next;
    for (int f : front)
      for (int n : nbr[f])
        if (!in[n]) in[n] = 1, next.push_back(n);
    front.swap(next);
  }
}

// build_rows writes the rows of one face consecutively: two per corner.
constexpr int kRowsPerFace = 6;

// The constraint rows C·y ≥ d of the faces in S, scaled by 1/h_t (dimensionless).
struct ConstraintRows {
  Eigen::SparseMatrix<double> C;  // m × #y
  Eigen::VectorXd d;              // m
  int faces = 0, skipped = 0;
  std::vector<int> face;  // #faces: the face of rows 6i … 6i + 5
};

// The constrained faces whose rows \p y violates most (by the scaled row value C y − d, most
// negative first), at most \p count: where an infeasible QP's last iterate stays folded.
std::vector<int> most_violated_faces(const ConstraintRows& rows, const Eigen::VectorXd& y,
                                     int count) {
  const Eigen::VectorXd r = rows.C * y - rows.d;
  std::vector<std::pair<double, int>> worst;  // (most negative row value, face)
  for (size_t i = 0; i < rows.face.size(); ++i) {
    const double w = r.segment(6 * static_cast<Eigen::Index>(i), 6).minCoeff();
    if (w < 0) worst.push_back({w, rows.face[i]});
  }
  const size_t n = std::min(worst.size(), static_cast<size_t>(std::max(count, 0)));
  std::partial_sort(worst.begin(), worst.begin() + n, worst.end());
  std::vector<int> out;
  for (size_t i = 0; i < n; ++i) out.push_back(worst[i].second);
  return out;
}

// ", most violated at faces a, b, c", or nothing without faces.
std::string faces_clause(const std::vector<int>& faces) {
  if (faces.empty()) return "";
  std::string s = ", most violated at face" + std::string(faces.size() > 1 ? "s " : " ");
  for (size_t i = 0; i < faces.size(); ++i) s += (i ? ", " : "") + std::to_string(faces[i]);
  return s;
}

ConstraintRows build_rows(const TriMesh& mesh, const GeometryCache& g,
                          const std::vector<std::array<std::array<double, 2>, 3>>& ideal,
                          const std::vector<int>& corner_wedge, const Reduction& red,
                          const std::vector<char>& in_set, double margin) {
  std::vector<Eigen::Triplet<double>> trip;
  int m = 0;
  ConstraintRows out;
  for (int f = 0; f < g.n_faces; ++f) {
    if (!in_set[f]) continue;
    Vec2 q[3], dir[3];
    bool ok = true;
    for (int k = 0; k < 3; ++k) {
      q[k] = Vec2(ideal[f][k][0], ideal[f][k][1]);
      const double len = q[k].norm();
      ok &= len > 0 && std::isfinite(len);
      dir[k] = ok ? Vec2(q[k] / len) : Vec2::Zero();
    }
    ok = ok && cross2(q[0], q[1]) > 0 && cross2(q[1], q[2]) > 0 && cross2(q[2], q[0]) > 0;
    if (!ok) {
      ++out.skipped;
      continue;
    }
    Vec2 ray[3];  // ray[k]: bisector of dir[k-1] and dir[k]; sector k runs from ray[k] to ray[k+1]
    for (int k = 0; k < 3; ++k) ray[k] = (dir[(k + 2) % 3] + dir[k]).normalized();
    double h = 0;
    for (int k = 0; k < 3; ++k) {
      const auto& a = mesh.point(mesh.vertex_handle(g.face_vertices[f][k]));
      const auto& b = mesh.point(mesh.vertex_handle(g.face_vertices[f][(k + 1) % 3]));
      h += (a - b).norm() / 3;
    }
    for (int k = 0; k < 3; ++k) {
      // Row 1: ray[k] × D_k ≥ ε; row 2: D_k × ray[k+1] ≥ ε, with D_k = Σ_j (δ_kj − ⅓) P_j.
      const Vec2 r1 = ray[k], r2 = ray[(k + 1) % 3];
      for (int j = 0; j < 3; ++j) {
        const double c = ((j == k) ? 1.0 : 0.0) - 1.0 / 3.0;
        const int w = corner_wedge[3 * f + j];
        trip.emplace_back(m, 2 * w, -r1.y() * c / h);
        trip.emplace_back(m, 2 * w + 1, r1.x() * c / h);
        trip.emplace_back(m + 1, 2 * w, r2.y() * c / h);
        trip.emplace_back(m + 1, 2 * w + 1, -r2.x() * c / h);
      }
      m += 2;
    }
    ++out.faces;
    out.face.push_back(f);
  }
  Eigen::SparseMatrix<double, Eigen::RowMajor> Cx(m, red.Z.rows());
  Cx.setFromTriplets(trip.begin(), trip.end());
  out.C = (Cx * red.Z).eval();
  out.C.prune(0.0);
  out.d = Eigen::VectorXd::Constant(m, margin) - Cx * red.z0;
  return out;
}

// The normal matrix M = A + Cᵀ·diag(D)·C of the interior-point steps, on a pattern fixed for
// one constraint set (lower triangle, as SpdSolver reads it). Cᵀ·diag(D)·C is the sum over the
// faces of their 6 rows' outer products, all on the face's few columns: the columns, the rows'
// coefficients and each column pair's slot in M's values are found once, and an iteration only
// accumulates (an Eigen product A + Cᵀ·D·C redid the symbolic product and allocated every
// iteration: 0.29 s of each 0.38 s iteration with all 70K faces of the bunny constrained).
class NormalMatrix {
 public:
  //! \p C: constraint rows, `group` consecutive rows per face (build_rows: kRowsPerFace).
  NormalMatrix(const Eigen::SparseMatrix<double>& A, const Eigen::SparseMatrix<double>& C,
               int group) {
    const int n = static_cast<int>(A.cols());
    // Pattern: lower triangle of A ∪ lower triangle of CᵀC (values 1: no cancellation).
    Eigen::SparseMatrix<double> C1 = C;
    for (int k = 0; k < C1.nonZeros(); ++k) C1.valuePtr()[k] = 1.0;
    Eigen::SparseMatrix<double> A1 = A;
    for (int k = 0; k < A1.nonZeros(); ++k) A1.valuePtr()[k] = 1.0;
    const Eigen::SparseMatrix<double> P = A1 + Eigen::SparseMatrix<double>(C1.transpose()) * C1;
    // Row-major round trip: sorted row indices in every column.
    const Eigen::SparseMatrix<double, Eigen::RowMajor> Pr = P.triangularView<Eigen::Lower>();
    M_ = Pr;
    M_.makeCompressed();
    base_.assign(M_.nonZeros(), 0.0);
    for (int j = 0; j < n; ++j)
      for (Eigen::SparseMatrix<double>::InnerIterator it(A, j); it; ++it)
        if (it.row() >= j) base_[slot(static_cast<int>(it.row()), j)] += it.value();
    // Faces: their columns (sorted, unique), the rows' coefficients on them, the pair slots.
    const Eigen::SparseMatrix<double, Eigen::RowMajor> Cr = C;
    const int m = static_cast<int>(C.rows());
    rows_ = m;
    group_ = group;
    std::vector<int> cols;
    for (int r0 = 0; r0 < m; r0 += group) {
      const int r1 = std::min(m, r0 + group);
      cols.clear();
      for (int r = r0; r < r1; ++r)
        for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(Cr, r); it; ++it)
          cols.push_back(static_cast<int>(it.col()));
      std::sort(cols.begin(), cols.end());
      cols.erase(std::unique(cols.begin(), cols.end()), cols.end());
      const int nc = static_cast<int>(cols.size());
      face_cols_.push_back(nc);
      face_coef_start_.push_back(static_cast<int>(coef_.size()));
      face_slot_start_.push_back(static_cast<int>(slots_.size()));
      for (int r = r0; r < r0 + group; ++r) {
        const size_t at = coef_.size();
        coef_.resize(at + nc, 0.0);
        if (r >= r1) continue;
        for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(Cr, r); it; ++it) {
          const int c = static_cast<int>(
              std::lower_bound(cols.begin(), cols.end(), static_cast<int>(it.col())) -
              cols.begin());
          coef_[at + c] += it.value();
        }
      }
      for (int a = 0; a < nc; ++a)
        for (int b = 0; b <= a; ++b) slots_.push_back(slot(cols[a], cols[b]));
    }
  }

  //! M for the weights \p D (one per row of C).
  const Eigen::SparseMatrix<double>& assemble(const Eigen::VectorXd& D) {
    double* v = M_.valuePtr();
    std::copy(base_.begin(), base_.end(), v);
    const int faces = static_cast<int>(face_cols_.size());
    for (int f = 0; f < faces; ++f) {
      const int nc = face_cols_[f];
      const double* coef = coef_.data() + face_coef_start_[f];
      const int* slot = slots_.data() + face_slot_start_[f];
      const int r0 = f * group_;
      const int nr = std::min(group_, rows_ - r0);
      for (int a = 0; a < nc; ++a)
        for (int b = 0; b <= a; ++b) {
          double sum = 0;
          for (int r = 0; r < nr; ++r) sum += D(r0 + r) * coef[r * nc + a] * coef[r * nc + b];
          v[*slot++] += sum;
        }
    }
    return M_;
  }

 private:
  // Index of entry (row i ≥ column j) in M_'s values.
  int slot(int i, int j) const {
    const int* begin = M_.innerIndexPtr() + M_.outerIndexPtr()[j];
    const int* end = M_.innerIndexPtr() + M_.outerIndexPtr()[j + 1];
    const int* it = std::lower_bound(begin, end, i);
    return static_cast<int>(it - M_.innerIndexPtr());
  }

  Eigen::SparseMatrix<double> M_;
  std::vector<double> base_;  // A's lower triangle on M_'s pattern
  int rows_ = 0, group_ = 1;
  std::vector<int> face_cols_, face_coef_start_, face_slot_start_;
  std::vector<double> coef_;  // per face: group × (its column count), row-major
  std::vector<int> slots_;    // per face: the lower pairs (a ≥ b) of its columns
};

// Primal-dual interior-point method (Mehrotra predictor-corrector) for
//   min ½yᵀAy − bᵀy  s.t.  Cy − s = d, s ≥ 0,
// Newton steps through the normal equations (A + Cᵀ diag(λ/s) C) Δy = …, factorized by
// CHOLMOD with one symbolic analysis. Infeasible start: y from the caller, s, λ > 0.
struct IpmOutcome {
  bool converged = false;
  bool infeasible = false;
  bool ordered = false;  // the normal matrix's analysis used the given ordering
  int iterations = 0;
  int clamp_reductions = 0;  // factorizations repeated with a lower λ/s clamp
  double primal_residual = 0;
};

IpmOutcome interior_point(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& b,
                          const Eigen::SparseMatrix<double>& C, const Eigen::VectorXd& d,
                          Eigen::VectorXd& y, int max_iterations, double tol,
                          const Observer* observer, const std::vector<int>* ordering) {
  IpmOutcome out;
  const int m = static_cast<int>(C.rows());
  const Eigen::SparseMatrix<double> Ct = C.transpose();
  SpdSolver solver("orientation constraints");
  if (ordering && !ordering->empty()) solver.set_ordering_hint(*ordering);
  NormalMatrix normal(A, C, kRowsPerFace);
  Eigen::VectorXd s = (C * y - d).cwiseMax(1.0);
  Eigen::VectorXd lambda = Eigen::VectorXd::Ones(m);
  const double b_scale = 1.0 + b.lpNorm<Eigen::Infinity>();

  // λ/s is clamped: on active constraints it grows without bound as s → 0, and beyond ~1e10
  // the normal matrix loses positive definiteness to rounding. Where it does so below that
  // bound, the clamp is lowered (by 100, down to kMinClamp) for this and the later iterations:
  // a damped, inexact Newton step instead of an error (the displaced pig's initial state, its
  // field-frame sectors: the 24th factorization failed at λ/s ≈ 9e9, and the method then
  // found the constraints infeasible). Not once a feasible iterate is kept: the method then
  // ends with it, as before.
  constexpr double kMinClamp = 1e6;
  double clamp = 1e10;
  auto factorize = [&](bool may_lower_clamp) {
    for (;;) {
      try {
        solver.factorize(normal.assemble(lambda.cwiseQuotient(s).cwiseMin(clamp)));
        break;
      } catch (const SolverError&) {
        if (!may_lower_clamp || clamp <= kMinClamp) throw;
        clamp /= 100;
        ++out.clamp_reductions;
      }
    }
    out.ordered = solver.stats().hinted_analyses > 0;
  };
  // Direction for complementarity target r_c (Λ Δs + S Δλ = r_c).
  auto direction = [&](const Eigen::VectorXd& rd, const Eigen::VectorXd& rp,
                       const Eigen::VectorXd& rc, Eigen::VectorXd& dy, Eigen::VectorXd& ds,
                       Eigen::VectorXd& dl) {
    const Eigen::VectorXd t = (rc - lambda.cwiseProduct(rp)).cwiseQuotient(s);
    dy = solver.solve(Eigen::VectorXd(-rd + Ct * t));
    ds = C * dy + rp;
    dl = (rc - lambda.cwiseProduct(ds)).cwiseQuotient(s);
  };
  auto max_step = [](const Eigen::VectorXd& v, const Eigen::VectorXd& dv) {
    double a = 1.0;
    for (int i = 0; i < v.size(); ++i)
      if (dv(i) < 0) a = std::min(a, -v(i) / dv(i));
    return a;
  };

  // Starting point (Nocedal & Wright §16.6): one affine step from (y, s, 1), then shift s
  // and λ away from zero.
  {
    factorize(true);
    const Eigen::VectorXd rd = A * y - b - Ct * lambda;
    const Eigen::VectorXd rp = C * y - s - d;
    Eigen::VectorXd dy, ds, dl;
    direction(rd, rp, -s.cwiseProduct(lambda), dy, ds, dl);
    s = (s + ds).cwiseAbs().cwiseMax(1.0);
    lambda = (lambda + dl).cwiseAbs().cwiseMax(1.0);
    ++out.iterations;
  }
  // Near the end the clamped λ/s makes the Newton steps inexact and the dual residual can
  // jump; the best iterate that satisfies the constraints (up to kFeasible, a tiny fraction of
  // the margin) is kept and returned when the tolerance is not reached. Once that iterate is
  // close (merit ≤ kNear), kStall iterations in a row without a better one end the method: the
  // 70K bunny with every face constrained reached merit 1.6e-9 in 21 iterations, then the dual
  // residual jumped between 1e-5 and 1 for the other 40 of max_iterations (9 s) while the
  // objective stayed the same to 1e-8.
  constexpr double kFeasible = 1e-6;
  constexpr double kNear = 1e-6;
  constexpr int kStall = 3;
  Eigen::VectorXd y_best;
  double best_merit = std::numeric_limits<double>::infinity();
  int since_best = 0;
  auto finish = [&]() {
    if (y_best.size() > 0) {
      y = y_best;
      out.primal_residual = 0;
    } else {
      out.infeasible = true;
    }
    return out;
  };
  for (int it = 0; it < max_iterations; ++it) {
    check_cancel(observer);
    const Eigen::VectorXd rd = A * y - b - Ct * lambda;
    const Eigen::VectorXd rp = C * y - s - d;
    const double mu = s.dot(lambda) / m;
    const double rd_rel = rd.lpNorm<Eigen::Infinity>() / b_scale;
    out.primal_residual = rp.lpNorm<Eigen::Infinity>();
    if (out.primal_residual <= tol && rd_rel <= tol && mu <= tol) {
      out.converged = true;
      return out;
    }
    if (out.primal_residual <= kFeasible && std::max(rd_rel, mu) < best_merit) {
      best_merit = std::max(rd_rel, mu);
      y_best = y;
      since_best = 0;
    } else if (best_merit <= kNear && ++since_best >= kStall) {
      return finish();  // stalled near the optimum
    }
    if (!std::isfinite(mu) || lambda.lpNorm<Eigen::Infinity>() > 1e14) {
      return finish();  // the multipliers diverge: no point satisfies C y ≥ d
    }
    try {
      factorize(y_best.size() == 0);
    } catch (const SolverError&) {
      if (y_best.size() > 0) return finish();  // rounding at the end of the iteration
      throw;
    }
    ++out.iterations;
    Eigen::VectorXd dy, ds, dl;
    direction(rd, rp, -s.cwiseProduct(lambda), dy, ds, dl);
    const double a_aff = std::min(max_step(s, ds), max_step(lambda, dl));
    const double mu_aff = (s + a_aff * ds).dot(lambda + a_aff * dl) / m;
    const double sigma = std::pow(mu_aff / mu, 3);
    const Eigen::VectorXd rc =
        -s.cwiseProduct(lambda) - ds.cwiseProduct(dl) + Eigen::VectorXd::Constant(m, sigma * mu);
    direction(rd, rp, rc, dy, ds, dl);
    const double a = std::min(1.0, 0.995 * std::min(max_step(s, ds), max_step(lambda, dl)));
    y += a * dy;
    s += a * ds;
    lambda += a * dl;
  }
  const Eigen::VectorXd rp = C * y - s - d;
  if (rp.lpNorm<Eigen::Infinity>() <= kFeasible) return out;  // the last iterate is feasible
  return finish();
}

// The same method on the dual QP  min ½λᵀSλ + gᵀλ, λ ≥ 0  (S PSD, dense m×m), whose optimality
// conditions s = Sλ + g ≥ 0, λ ≥ 0, s∘λ = 0 are those of the primal QP with y = y0 + Wλ.
// Newton steps: (S + diag(s/λ)) Δλ = r_c/λ − r_p, Δs = SΔλ + r_p (dense Cholesky).
IpmOutcome interior_point_dual(const Eigen::MatrixXd& S, const Eigen::VectorXd& g,
                               Eigen::VectorXd& lambda, int max_iterations, double tol,
                               const Observer* observer) {
  IpmOutcome out;
  const int m = static_cast<int>(S.rows());
  lambda = Eigen::VectorXd::Ones(m);
  Eigen::VectorXd s = (S * lambda + g).cwiseMax(1.0);
  Eigen::LLT<Eigen::MatrixXd> llt;
  auto factorize = [&]() {
    Eigen::MatrixXd M = S;
    M.diagonal() += s.cwiseQuotient(lambda).cwiseMin(1e12);
    llt.compute(M);
    if (llt.info() != Eigen::Success)
      throw SolverError("orientation constraints: dual Newton matrix not positive definite");
  };
  auto direction = [&](const Eigen::VectorXd& rp, const Eigen::VectorXd& rc, Eigen::VectorXd& dl,
                       Eigen::VectorXd& ds) {
    dl = llt.solve(Eigen::VectorXd(rc.cwiseQuotient(lambda) - rp));
    ds = S * dl + rp;
  };
  auto max_step = [](const Eigen::VectorXd& v, const Eigen::VectorXd& dv) {
    double a = 1.0;
    for (int i = 0; i < v.size(); ++i)
      if (dv(i) < 0) a = std::min(a, -v(i) / dv(i));
    return a;
  };
  {
    factorize();
    const Eigen::VectorXd rp = S * lambda + g - s;
    Eigen::VectorXd dl, ds;
    direction(rp, -s.cwiseProduct(lambda), dl, ds);
    s = (s + ds).cwiseAbs().cwiseMax(1.0);
    lambda = (lambda + dl).cwiseAbs().cwiseMax(1.0);
    ++out.iterations;
  }
  for (int it = 0; it < max_iterations; ++it) {
    check_cancel(observer);
    const Eigen::VectorXd rp = S * lambda + g - s;
    const double mu = s.dot(lambda) / m;
    out.primal_residual = rp.lpNorm<Eigen::Infinity>();
    if (out.primal_residual <= tol && mu <= tol) {
      out.converged = true;
      return out;
    }
    if (!std::isfinite(mu) || lambda.lpNorm<Eigen::Infinity>() > 1e14) {
      out.infeasible = true;
      return out;
    }
    try {
      factorize();
    } catch (const SolverError&) {
      if (out.primal_residual <= 1e-7 && mu <= 1e-7) {
        out.converged = true;
        return out;
      }
      throw;
    }
    ++out.iterations;
    Eigen::VectorXd dl, ds;
    direction(rp, -s.cwiseProduct(lambda), dl, ds);
    const double a_aff = std::min(max_step(s, ds), max_step(lambda, dl));
    const double mu_aff = (s + a_aff * ds).dot(lambda + a_aff * dl) / m;
    const double sigma = std::pow(mu_aff / mu, 3);
    const Eigen::VectorXd rc =
        -s.cwiseProduct(lambda) - ds.cwiseProduct(dl) + Eigen::VectorXd::Constant(m, sigma * mu);
    direction(rp, rc, dl, ds);
    const double a = std::min(1.0, 0.995 * std::min(max_step(s, ds), max_step(lambda, dl)));
    lambda += a * dl;
    s += a * ds;
  }
  const Eigen::VectorXd rp = S * lambda + g - s;
  out.primal_residual = rp.lpNorm<Eigen::Infinity>();
  // s ≥ 0 always; the constraints hold up to the residual, far below the margin.
  out.infeasible = out.primal_residual > 1e-6;
  return out;
}

// solution_frame_angles (header) with the face adjacency at hand.
std::vector<double> map_frame_angles(const GeometryCache& g, const std::vector<double>& theta,
                                     const std::vector<int>& corner_wedge, const Eigen::VectorXd& x,
                                     const std::vector<std::vector<int>>& nbr) {
  const int nf = g.n_faces;
  std::vector<double> out(theta);
  // Unit complex e^{iδ} of the rotation from the field frame to the map's closest rotation.
  std::vector<std::complex<double>> rot(nf, 0.0);
  std::vector<char> known(nf, 0);
  for (int f = 0; f < nf; ++f) {
    // Jacobian of the map in the face frame: J = Σ_k x(corner k) ⊗ ∇φ_k (cached gradients).
    const auto& grad = g.face_gradient[f];
    if (!(grad[6] > 0)) continue;  // degenerate 3D triangle
    Eigen::Matrix2d J = Eigen::Matrix2d::Zero();
    for (int k = 0; k < 3; ++k) {
      const int w = corner_wedge[3 * f + k];
      J += Vec2(x(2 * w), x(2 * w + 1)) * Eigen::RowVector2d(grad[2 * k], grad[2 * k + 1]);
    }
    if (!(J.determinant() > 0)) continue;  // folded or collapsed by the map
    // Closest rotation R(ψ) to J; the frame (cos θ', sin θ') maps q to R(−θ')q, so θ' = −ψ.
    const double psi = std::atan2(J(1, 0) - J(0, 1), J(0, 0) + J(1, 1));
    rot[f] = std::polar(1.0, -psi - theta[f]);
    known[f] = 1;
  }
  // Folded or degenerate faces: the mean rotation of known neighbours, ring by ring.
  std::vector<int> frontier;
  for (int f = 0; f < nf; ++f)
    if (!known[f]) frontier.push_back(f);
  while (!frontier.empty()) {
    std::vector<int> next;
    std::vector<std::pair<int, std::complex<double>>> fill;
    for (int f : frontier) {
      std::complex<double> sum = 0.0;
      for (int n : nbr[f])
        if (known[n]) sum += rot[n];
      if (std::abs(sum) > 1e-12)
        fill.emplace_back(f, sum / std::abs(sum));
      else
        next.push_back(f);
    }
    if (fill.empty()) break;  // components without any known face keep the field frame
    for (const auto& [f, r] : fill) rot[f] = r, known[f] = 1;
    frontier.swap(next);
  }
  // At most kMaxSectorTurn from the field frame: the frames then keep the field's winding
  // around every vertex (an unbounded turn let a valence-5 node of fertility's cage layout end
  // with a 90° cone instead of 450°, every face oriented).
  for (int f = 0; f < nf; ++f)
    if (known[f]) out[f] = theta[f] + std::clamp(std::arg(rot[f]), -kMaxSectorTurn, kMaxSectorTurn);
  return out;
}

}  // namespace

std::vector<std::array<std::array<double, 2>, 3>> ideal_corner_offsets(
    const TriMesh& mesh, const GeometryCache& g, const std::vector<double>& theta) {
  std::vector<std::array<std::array<double, 2>, 3>> out(g.n_faces);
  for (int f = 0; f < g.n_faces; ++f) {
    const auto p = face_corners_2d(mesh, g, f);
    const Vec2 c = (Vec2(p[0][0], p[0][1]) + Vec2(p[1][0], p[1][1]) + Vec2(p[2][0], p[2][1])) / 3;
    const Vec2 u(std::cos(theta[f]), std::sin(theta[f])), v(-u.y(), u.x());
    const double a2 = cross2(Vec2(p[1][0] - p[0][0], p[1][1] - p[0][1]),
                             Vec2(p[2][0] - p[0][0], p[2][1] - p[0][1]));
    for (int k = 0; k < 3; ++k) {
      const Vec2 q = Vec2(p[k][0], p[k][1]) - c;
      out[f][k] =
          a2 > 0 ? std::array<double, 2>{q.dot(u), q.dot(v)} : std::array<double, 2>{0.0, 0.0};
    }
  }
  return out;
}

std::vector<double> solution_frame_angles(const GeometryCache& g, const std::vector<double>& theta,
                                          const std::vector<int>& corner_wedge,
                                          const Eigen::VectorXd& x) {
  if (static_cast<int>(theta.size()) != g.n_faces ||
      static_cast<int>(corner_wedge.size()) != 3 * g.n_faces ||
      static_cast<int>(g.face_gradient.size()) != g.n_faces)
    throw InvalidInputError("solution_frame_angles: inconsistent sizes");
  for (int w : corner_wedge)
    if (w < 0 || 2 * static_cast<Eigen::Index>(w) + 1 >= x.size())
      throw InvalidInputError("solution_frame_angles: corner wedge out of range");
  return map_frame_angles(g, theta, corner_wedge, x, face_neighbours(g));
}

int count_foldovers(const std::vector<int>& corner_wedge, const Eigen::VectorXd& x,
                    std::vector<char>* folded) {
  const int nf = static_cast<int>(corner_wedge.size() / 3);
  if (folded) folded->assign(nf, 0);
  int count = 0;
  for (int f = 0; f < nf; ++f) {
    const int a = corner_wedge[3 * f], b = corner_wedge[3 * f + 1], c = corner_wedge[3 * f + 2];
    const double area2 = (x(2 * b) - x(2 * a)) * (x(2 * c + 1) - x(2 * a + 1)) -
                         (x(2 * b + 1) - x(2 * a + 1)) * (x(2 * c) - x(2 * a));
    if (area2 <= 0) {
      ++count;
      if (folded) (*folded)[f] = 1;
    }
  }
  return count;
}

namespace {

// solve_oriented with the sectors of the frame angles \p sector_theta (its inputs checked; y0
// folds). Fills \p rep from scratch except ran/foldovers_before.
Eigen::VectorXd solve_in_frame(const TriMesh& mesh, const GeometryCache& g,
                               const std::vector<double>& sector_theta,
                               const std::vector<int>& corner_wedge, const Reduction& red,
                               const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& b,
                               const Eigen::VectorXd& y0, const OrientationOptions& o,
                               const std::vector<char>& folded,
                               const std::vector<std::vector<int>>& nbr, OrientationReport& rep,
                               SpdSolver* factorized_A, const std::vector<int>* ordering) {
  const auto t0 = std::chrono::steady_clock::now();
  rep.foldovers_after = rep.foldovers_before;
  const auto ideal = ideal_corner_offsets(mesh, g, sector_theta);
  const double h = g.mean_edge_length > 0 ? g.mean_edge_length : 1.0;
  // Scaled objective (A/h, b/h): residuals and multipliers of order one.
  const Eigen::SparseMatrix<double> As = A / h;
  const Eigen::VectorXd bs = b / h;
  std::vector<char> in_set = folded;
  Eigen::VectorXd y = y0;
  // The round with the fewest fold-overs so far (when a later round turns out infeasible).
  Eigen::VectorXd best_y;
  int best_folds = rep.foldovers_before;
  auto dense_for = [&](double m) {
    return factorized_A && factorized_A->factorized() && m <= o.dense_max_rows &&
           m * static_cast<double>(A.cols()) <= o.dense_max_entries &&
           m * m * m <= o.dense_cost_ratio * std::pow(static_cast<double>(A.cols()), 1.5);
  };
  // Every face at once after all_faces_after_rounds sparse rounds that left fold-overs outside
  // their set; no longer once such a round was infeasible.
  bool all_faces = false, all_faces_allowed = o.all_faces_after_rounds > 0;
  int unfinished_sparse_rounds = 0;
  Eigen::VectorXd y_round = y;  // the iterate before an all-faces round
  std::vector<char> round_set;
  for (int round = 0; round < o.max_rounds; ++round) {
    check_cancel(o.observer);
    if (all_faces)
      std::fill(in_set.begin(), in_set.end(), 1);
    else
      grow(nbr, o.rings, in_set);
    rep.all_faces = all_faces;
    const ConstraintRows rows = build_rows(mesh, g, ideal, corner_wedge, red, in_set, o.margin);
    rep.constrained_faces = rows.faces;
    rep.skipped_faces = rows.skipped;
    ++rep.rounds;
    if (rows.C.rows() == 0) break;
    const bool dense = dense_for(static_cast<double>(rows.C.rows()));
    rep.dense = dense;
    rep.infeasible_faces.clear();
    IpmOutcome ipm;
    if (dense) {
      // W = A⁻¹Cᵀ (m back-substitutions); for the scaled objective A/h: y = y0 + h·W·λ.
      const Eigen::MatrixXd W = factorized_A->solve(Eigen::MatrixXd(rows.C.transpose()));
      const Eigen::MatrixXd S = h * (rows.C * W);
      const Eigen::VectorXd g = rows.C * y0 - rows.d;
      Eigen::VectorXd lambda;
      ipm = interior_point_dual(0.5 * (S + S.transpose()), g, lambda, o.max_iterations, o.tolerance,
                                o.observer);
      y = y0 + h * (W * lambda);
    } else {
      ipm = interior_point(As, bs, rows.C, rows.d, y, o.max_iterations, o.tolerance, o.observer,
                           ordering);
      rep.sparse_factorizations += ipm.iterations;
      rep.clamp_reductions += ipm.clamp_reductions;
      rep.ordered_rounds += ipm.ordered;
    }
    rep.iterations += ipm.iterations;
    if (ipm.infeasible) rep.infeasible_faces = most_violated_faces(rows, y, kNamedFaces);
    if (ipm.infeasible && all_faces) {
      if (o.stop_if_all_faces_infeasible) {
        rep.message = "orientation constraints are infeasible on every face (round " +
                      std::to_string(round + 1) + faces_clause(rep.infeasible_faces) +
                      "); kept the best earlier solution (" + std::to_string(best_folds) +
                      " fold-overs)";
        rep.all_faces = true;
        rep.foldovers_after = best_folds;
        rep.time_s = seconds_since(t0);
        return best_y.size() > 0 ? best_y : y0;
      }
      // Too strict everywhere: back to the set of the rounds (grown by the faces the last
      // round folded), rounds only from here on.
      all_faces = false;
      all_faces_allowed = false;
      in_set = round_set;
      y = y_round;
      continue;
    }
    if (ipm.infeasible) {
      std::ostringstream ss;
      ss << "orientation constraints are infeasible on " << rows.faces
         << " constrained faces (round " << round + 1 << ", primal residual " << ipm.primal_residual
         << faces_clause(rep.infeasible_faces) << ")";
      rep.message = ss.str();
      rep.time_s = seconds_since(t0);
      if (best_y.size() == 0) throw SolverError(rep.message);
      rep.message +=
          "; kept the best earlier round (" + std::to_string(best_folds) + " fold-overs)";
      rep.foldovers_after = best_folds;
      return best_y;
    }
    std::vector<char> now;
    rep.foldovers_after = count_foldovers(corner_wedge, red.Z * y + red.z0, &now);
    if (rep.foldovers_after < best_folds) best_folds = rep.foldovers_after, best_y = y;
    if (rep.foldovers_after == 0) break;
    bool added = false;
    for (int f = 0; f < g.n_faces; ++f)
      if (now[f] && !in_set[f]) in_set[f] = 1, added = true;
    if (!added) break;  // only skipped (degenerate) faces remain folded
    if (!dense && all_faces_allowed && ++unfinished_sparse_rounds >= o.all_faces_after_rounds) {
      round_set = in_set;
      y_round = y;
      all_faces = true;
    }
  }
  if (best_y.size() > 0 && best_folds < rep.foldovers_after) {
    y = best_y;
    rep.foldovers_after = best_folds;
  }
  if (rep.foldovers_after > 0 && rep.message.empty()) {
    std::ostringstream ss;
    ss << rep.foldovers_after << " fold-over(s) remain after " << rep.rounds << " round(s)";
    rep.message = ss.str();
  }
  rep.time_s = seconds_since(t0);
  return y;
}

// Adds the effort of another attempt to \p into (its counts, its time).
void add_effort(OrientationReport& into, const OrientationReport& other) {
  into.rounds += other.rounds;
  into.iterations += other.iterations;
  into.sparse_factorizations += other.sparse_factorizations;
  into.clamp_reductions += other.clamp_reductions;
  into.ordered_rounds += other.ordered_rounds;
  into.time_s += other.time_s;
}

}  // namespace

Eigen::VectorXd solve_oriented(const TriMesh& mesh, const GeometryCache& g,
                               const std::vector<double>& theta,
                               const std::vector<int>& corner_wedge, const Reduction& red,
                               const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& b,
                               const Eigen::VectorXd& y0, const OrientationOptions& o,
                               OrientationReport* report, SpdSolver* factorized_A,
                               const std::vector<int>* ordering) {
  OrientationReport local;
  OrientationReport& rep = report ? *report : local;
  rep = OrientationReport{};
  rep.ran = true;
  if (static_cast<int>(corner_wedge.size()) != 3 * g.n_faces ||
      static_cast<int>(theta.size()) != g.n_faces || y0.size() != A.cols() ||
      b.size() != A.rows() || red.Z.cols() != A.cols())
    throw InvalidInputError("orientation constraints: inconsistent problem sizes");
  if (!(o.margin > 0) || o.rings < 0 || o.max_rounds < 1 || o.max_iterations < 1)
    throw InvalidInputError("orientation constraints: invalid options");
  if (o.sector_frame != SectorFrame::kField &&
      static_cast<int>(g.face_gradient.size()) != g.n_faces)
    throw InvalidInputError(
        "orientation constraints: solution-frame sectors need the geometry's face gradients");

  std::vector<char> folded;
  const Eigen::VectorXd x0 = red.Z * y0 + red.z0;
  rep.foldovers_before = count_foldovers(corner_wedge, x0, &folded);
  rep.foldovers_after = rep.foldovers_before;
  if (rep.foldovers_before == 0) return y0;
  const auto nbr = face_neighbours(g);
  const int foldovers_before = rep.foldovers_before;
  auto attempt = [&](SectorFrame frame, OrientationReport& r) {
    r = OrientationReport{};
    r.ran = true;
    r.foldovers_before = foldovers_before;
    r.sector_frame = frame;
    const std::vector<double> sector_theta =
        frame == SectorFrame::kSolution ? map_frame_angles(g, theta, corner_wedge, x0, nbr) : theta;
    return solve_in_frame(mesh, g, sector_theta, corner_wedge, red, A, b, y0, o, folded, nbr, r,
                          factorized_A, ordering);
  };
  if (o.sector_frame != SectorFrame::kFieldThenSolution) return attempt(o.sector_frame, rep);

  // Field-frame sectors first; where fold-overs remain (or the QP is infeasible), the
  // solution frame's too, and the attempt with fewer fold-overs is kept (ties: the first).
  auto name = [](SectorFrame f) {
    return std::string(f == SectorFrame::kField ? "field" : "solution") + "-frame sectors";
  };
  auto account = [&](const OrientationReport& r) {
    return name(r.sector_frame) + ": " +
           (r.message.empty() ? std::to_string(r.foldovers_after) + " fold-over(s) remain"
                              : r.message);
  };
  // An attempt whose QP gives no solution (SolverError) is recorded as failed, with its message.
  auto guarded = [&](SectorFrame frame, OrientationReport& r, Eigen::VectorXd& y) {
    try {
      y = attempt(frame, r);
      return true;
    } catch (const SolverError& e) {
      if (r.message.empty()) r.message = e.what();
      return false;
    }
  };
  OrientationReport first, second;
  Eigen::VectorXd y_first, y_second;
  const bool first_failed = !guarded(SectorFrame::kField, first, y_first);
  if (!first_failed && first.foldovers_after == 0) {
    rep = first;
    return y_first;
  }
  const bool second_failed = !guarded(SectorFrame::kSolution, second, y_second);
  const bool keep_first =
      second_failed || (!first_failed && first.foldovers_after <= second.foldovers_after);
  const OrientationReport& kept = keep_first ? first : second;
  const OrientationReport& other = keep_first ? second : first;
  rep = kept;
  add_effort(rep, other);
  rep.message = account(kept) + "; " + account(other);
  if (first_failed && second_failed) throw SolverError(rep.message);
  return keep_first ? y_first : y_second;
}

}  // namespace qs
