#include "core/param/untangle.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <future>
#include <limits>
#include <thread>

#include "core/base/errors.h"
#include "core/base/spd_solver.h"
#include "core/param/orientation.h"

namespace qs {

namespace {

using Vec4 = Eigen::Matrix<double, 4, 1>;
using Mat4 = Eigen::Matrix<double, 4, 4>;

// The Jacobian of one face as an affine function of the reduced unknowns it depends on:
// vec(J) = (∂u/∂e1, ∂u/∂e2, ∂v/∂e1, ∂v/∂e2) = L · y[cols] + j0, L of size 4 × cols.size().
struct FaceJacobians {
  std::vector<int> offset;   // per face: start in cols (size #F + 1)
  std::vector<int> cols;     // reduced unknowns of each face, ascending
  std::vector<double> L;     // per face 4 × k, column-major, at 4·offset[f]
  std::vector<Vec4> j0;      // per face
  std::vector<double> area;  // per face (0: degenerate, skipped)
  std::vector<int> slot;     // per face: k(k+1)/2 slots of M's values (lower triangle, j ≤ i)
  std::vector<int> slot_offset;
};

double chi(double D, double eps) {
  return 0.5 * (D + std::sqrt(eps * eps + D * D));
}

// F(J) = |J|²/χ(det J, ε), its gradient and Hessian in vec(J) = (a, b, c, d), J = [a b; c d].
// F(J) = (1 − λ)·|J|²/χ(D, ε) + λ·(D² + D0²)/(D0·χ(D, ε)), D = det J, its gradient and
// Hessian in vec(J) = (a, b, c, d), J = [a b; c d]. The first (conformal) term alone lets a
// face escape the barrier by collapsing (J → 0); the second (area) term, minimal at D = D0,
// forbids that.
double barrier(const Vec4& J, double eps, double lambda, double D0, Vec4* grad, Mat4* hess) {
  const double a = J(0), b = J(1), c = J(2), d = J(3);
  const double D = a * d - b * c, T = J.squaredNorm();
  const double r = std::sqrt(eps * eps + D * D);
  const double x = chi(D, eps);
  const double S = (D * D + D0 * D0) / D0;
  const double F = ((1 - lambda) * T + lambda * S) / x;
  if (!grad) return F;
  const double x1 = x / r;                          // χ'
  const double x2 = 0.5 * eps * eps / (r * r * r);  // χ''
  const Vec4 gT = 2 * J;
  const Vec4 gD(d, -c, -b, a);
  // conformal part: T/χ
  const double c1 = 1 - lambda;
  // area part as a function of D: G(D) = S/χ
  const double G1 = 2 * D / D0 / x - S * x1 / (x * x);
  const double G2 =
      2 / (D0 * x) - 4 * D / D0 * x1 / (x * x) + S * (2 * x1 * x1 / (x * x * x) - x2 / (x * x));
  *grad = c1 * (gT / x - (T * x1 / (x * x)) * gD) + lambda * G1 * gD;
  if (hess) {
    Mat4 HD = Mat4::Zero();
    HD(0, 3) = HD(3, 0) = 1;
    HD(1, 2) = HD(2, 1) = -1;
    *hess = c1 * ((2 / x) * Mat4::Identity() -
                  (x1 / (x * x)) * (gT * gD.transpose() + gD * gT.transpose()) +
                  T * (2 * x1 * x1 / (x * x * x) - x2 / (x * x)) * (gD * gD.transpose()) -
                  (T * x1 / (x * x)) * HD) +
            lambda * (G2 * (gD * gD.transpose()) + G1 * HD);
  }
  return F;
}

// The nearest positive semidefinite matrix (eigenvalues clamped at 0); a positive definite H,
// which a Cholesky factorization recognizes cheaply, is returned as it is.
Mat4 project_psd(const Mat4& H) {
  if (Eigen::LLT<Mat4>(H).info() == Eigen::Success) return H;
  Eigen::SelfAdjointEigenSolver<Mat4> es(H);
  Vec4 ev = es.eigenvalues();
  for (int i = 0; i < 4; ++i) ev(i) = std::max(ev(i), 0.0);
  return es.eigenvectors() * ev.asDiagonal() * es.eigenvectors().transpose();
}

FaceJacobians face_jacobians(const GeometryCache& g, const std::vector<int>& corner_wedge,
                             const Reduction& red) {
  const Eigen::SparseMatrix<double, Eigen::RowMajor> Zr = red.Z;
  FaceJacobians fj;
  fj.offset.assign(g.n_faces + 1, 0);
  fj.j0.resize(g.n_faces);
  fj.area.resize(g.n_faces);
  std::vector<int> cols;
  std::vector<std::pair<int, Vec4>> terms;  // (column, coefficient on vec(J))
  for (int f = 0; f < g.n_faces; ++f) {
    const std::array<double, 7>& gr = g.face_gradient[f];
    fj.area[f] = gr[6] > 0 && std::isfinite(gr[6]) ? gr[6] : 0.0;
    Vec4 j0 = Vec4::Zero();
    terms.clear();
    for (int k = 0; k < 3; ++k) {
      const int w = corner_wedge[3 * f + k];
      for (int comp = 0; comp < 2; ++comp) {
        const int xi = 2 * w + comp;
        Vec4 coef = Vec4::Zero();
        coef(2 * comp) = gr[2 * k];
        coef(2 * comp + 1) = gr[2 * k + 1];
        j0 += red.z0(xi) * coef;
        for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(Zr, xi); it; ++it)
          terms.emplace_back(static_cast<int>(it.col()), it.value() * coef);
      }
    }
    std::sort(terms.begin(), terms.end(),
              [](const auto& p, const auto& q) { return p.first < q.first; });
    for (size_t i = 0; i < terms.size(); ++i) {
      if (i > 0 && terms[i].first == terms[i - 1].first) {
        const int k = static_cast<int>(fj.cols.size()) - 1;
        for (int r = 0; r < 4; ++r) fj.L[4 * k + r] += terms[i].second(r);
        continue;
      }
      fj.cols.push_back(terms[i].first);
      for (int r = 0; r < 4; ++r) fj.L.push_back(terms[i].second(r));
    }
    fj.offset[f + 1] = static_cast<int>(fj.cols.size());
    fj.j0[f] = j0;
  }
  return fj;
}

double det_of(const Vec4& J) {
  return J(0) * J(3) - J(1) * J(2);
}

Vec4 jacobian_of(const FaceJacobians& fj, int f, const Eigen::VectorXd& y) {
  Vec4 J = fj.j0[f];
  for (int i = fj.offset[f]; i < fj.offset[f + 1]; ++i)
    J += y(fj.cols[i]) * Eigen::Map<const Vec4>(&fj.L[4 * i]);
  return J;
}

// Runs body(begin, end) over [0, n) in two halves, the second on another thread when asked.
template <class Body>
void two_halves(int n, bool second_thread, const Body& body) {
  const int mid = n / 2;
  if (second_thread) {
    auto second = std::async(std::launch::async, [&body, mid, n] { body(1, mid, n); });
    body(0, 0, mid);
    second.get();
  } else {
    body(0, 0, mid);
    body(1, mid, n);
  }
}

}  // namespace

Eigen::VectorXd untangle(const GeometryCache& g, const std::vector<int>& corner_wedge,
                         const Reduction& red, const Eigen::SparseMatrix<double>& A,
                         const Eigen::VectorXd& b, const Eigen::VectorXd& y_start,
                         const UntangleOptions& o, UntangleReport* report) {
  const auto t0 = std::chrono::steady_clock::now();
  UntangleReport local;
  UntangleReport& rep = report ? *report : local;
  rep = UntangleReport{};
  rep.ran = true;
  const int n = static_cast<int>(A.cols());
  if (static_cast<int>(corner_wedge.size()) != 3 * g.n_faces || y_start.size() != n ||
      b.size() != n || red.Z.cols() != n || static_cast<int>(g.face_gradient.size()) != g.n_faces)
    throw InvalidInputError("untangle: inconsistent problem sizes or no face gradients");
  if (!(o.beta > 0) || !(o.initial_epsilon > 0) || !(o.min_epsilon > 0) || !(o.area_weight > 0) ||
      !(o.area_weight <= 1) || !(o.min_sigma > 0) || !(o.min_sigma < 1) || o.newton_per_round < 1 ||
      o.max_newton < 0)
    throw InvalidInputError("untangle: invalid options");
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };

  FaceJacobians fj = face_jacobians(g, corner_wedge, red);
  double total_area = 0;
  for (double a : fj.area) total_area += a;
  if (!(total_area > 0)) throw InvalidInputError("untangle: the mesh has no area");
  const double mu = 1.0 / total_area;

  // M's pattern: A's lower triangle and every face's block; the slots of each face's pairs.
  const Eigen::SparseMatrix<double> A_full = A.selfadjointView<Eigen::Lower>();
  Eigen::SparseMatrix<double> M(n, n);
  {
    std::vector<Eigen::Triplet<double>> trip;
    trip.reserve(A_full.nonZeros() / 2 + n + 40 * static_cast<size_t>(g.n_faces));
    for (int c = 0; c < n; ++c) {
      trip.emplace_back(c, c, 0.0);
      for (Eigen::SparseMatrix<double>::InnerIterator it(A_full, c); it; ++it)
        if (it.row() >= c) trip.emplace_back(static_cast<int>(it.row()), c, 0.0);
    }
    for (int f = 0; f < g.n_faces; ++f)
      for (int i = fj.offset[f]; i < fj.offset[f + 1]; ++i)
        for (int j = fj.offset[f]; j <= i; ++j) trip.emplace_back(fj.cols[i], fj.cols[j], 0.0);
    M.setFromTriplets(trip.begin(), trip.end());
    M.makeCompressed();
  }
  auto slot_of = [&](int row, int col) {
    const int* begin = M.innerIndexPtr() + M.outerIndexPtr()[col];
    const int* end = M.innerIndexPtr() + M.outerIndexPtr()[col + 1];
    return static_cast<int>(std::lower_bound(begin, end, row) - M.innerIndexPtr());
  };
  fj.slot_offset.assign(g.n_faces + 1, 0);
  for (int f = 0; f < g.n_faces; ++f) {
    for (int i = fj.offset[f]; i < fj.offset[f + 1]; ++i)
      for (int j = fj.offset[f]; j <= i; ++j) fj.slot.push_back(slot_of(fj.cols[i], fj.cols[j]));
    fj.slot_offset[f + 1] = static_cast<int>(fj.slot.size());
  }
  std::vector<int> diag_slot(n);
  for (int c = 0; c < n; ++c) diag_slot[c] = slot_of(c, c);
  std::vector<std::pair<int, double>> a_slots;  // (slot of M, value of A), lower triangle
  for (int c = 0; c < n; ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(A_full, c); it; ++it)
      if (it.row() >= c) a_slots.emplace_back(slot_of(static_cast<int>(it.row()), c), it.value());

  // ε in units of det J: the median determinant of the unfolded faces.
  std::vector<double> dets;
  for (int f = 0; f < g.n_faces; ++f) {
    if (fj.area[f] <= 0) continue;
    const double D = det_of(jacobian_of(fj, f, y_start));
    if (D > 0) dets.push_back(D);
  }
  double det_scale = 1.0;
  if (!dets.empty()) {
    std::nth_element(dets.begin(), dets.begin() + dets.size() / 2, dets.end());
    det_scale = dets[dets.size() / 2];
  }
  const double lambda = o.area_weight;
  const bool two_threads =
      o.second_thread && g.n_faces >= 8000 && std::thread::hardware_concurrency() >= 2;
  auto quadratic = [&](const Eigen::VectorXd& y) { return 0.5 * y.dot(A_full * y) - b.dot(y); };
  // Σ_t a_t F_ε(J_t) (alone: σ of the ε rule) and the smallest determinant (when asked).
  // Each half of the faces sums on its own; the halves are added in order, so the value does
  // not depend on the thread count.
  auto barrier_sum = [&](const Eigen::VectorXd& yy, double e, double* d_min = nullptr) {
    std::array<double, 2> sum{0, 0};
    std::array<double, 2> lowest{std::numeric_limits<double>::infinity(),
                                 std::numeric_limits<double>::infinity()};
    two_halves(g.n_faces, two_threads, [&](int half, int begin, int end) {
      for (int f = begin; f < end; ++f) {
        if (fj.area[f] <= 0) continue;
        const Vec4 J = jacobian_of(fj, f, yy);
        lowest[half] = std::min(lowest[half], det_of(J));
        sum[half] += fj.area[f] * barrier(J, e, lambda, det_scale, nullptr, nullptr);
      }
    });
    if (d_min) *d_min = std::min(lowest[0], lowest[1]);
    return sum[0] + sum[1];
  };
  // The faces' weighted gradients and projected Hessians, summed by each half of the faces into
  // its own copy of the gradient and of M's values (no locks; the two copies are added after).
  std::array<std::vector<double>, 2> part_grad, part_hess;
  for (int h = 0; h < 2; ++h) {
    part_grad[h].resize(n);
    part_hess[h].resize(M.nonZeros());
  }
  auto face_terms = [&](const Eigen::VectorXd& yy, double e) {
    two_halves(g.n_faces, two_threads, [&](int half, int begin, int end) {
      double* gv = part_grad[half].data();
      double* hv = part_hess[half].data();
      std::fill(gv, gv + n, 0.0);
      std::fill(hv, hv + M.nonZeros(), 0.0);
      Mat4 H4;
      Vec4 g4;
      std::vector<Vec4> PL;  // P · (column j of the face's L)
      for (int f = begin; f < end; ++f) {
        if (fj.area[f] <= 0) continue;
        const int k = fj.offset[f + 1] - fj.offset[f];
        barrier(jacobian_of(fj, f, yy), e, lambda, det_scale, &g4, &H4);
        const Mat4 P = project_psd(H4);
        const double w = o.beta * fj.area[f];
        const double* L = &fj.L[4 * fj.offset[f]];
        const int* col = &fj.cols[fj.offset[f]];
        PL.resize(k);
        for (int j = 0; j < k; ++j) {
          const Eigen::Map<const Vec4> Lj(L + 4 * j);
          gv[col[j]] += w * Lj.dot(g4);
          PL[j] = w * (P * Lj);
        }
        const int* slot = &fj.slot[fj.slot_offset[f]];
        for (int i = 0; i < k; ++i) {
          const Eigen::Map<const Vec4> Li(L + 4 * i);
          for (int j = 0; j <= i; ++j) hv[*slot++] += Li.dot(PL[j]);
        }
      }
    });
  };
  auto phi = [&](const Eigen::VectorXd& y, double eps) {
    return mu * quadratic(y) + o.beta * barrier_sum(y, eps);
  };
  auto foldovers = [&](const Eigen::VectorXd& y) {
    return count_foldovers(corner_wedge, red.Z * y + red.z0);
  };

  Eigen::VectorXd y = y_start;
  rep.foldovers_before = foldovers(y);
  rep.foldovers_after = rep.foldovers_before;
  if (rep.foldovers_before == 0) {
    rep.time_s = elapsed();
    return y;
  }
  Eigen::VectorXd best = y;
  int best_folds = rep.foldovers_before;
  double best_q = quadratic(y);

  double eps = o.initial_epsilon * det_scale;

  SpdSolver solver("untangling");
  Eigen::VectorXd grad(n), step(n), trial(n);
  while (rep.newton_steps < o.max_newton) {
    ++rep.rounds;
    double d_min = 0;
    const double barrier_before = barrier_sum(y, eps, &d_min);
    double value = phi(y, eps);
    bool moved = false, broken = false;
    for (int it = 0; it < o.newton_per_round && rep.newton_steps < o.max_newton; ++it) {
      check_cancel(o.observer);
      // Gradient and projected Hessian of Φ_ε.
      face_terms(y, eps);
      for (Eigen::Index s = 0; s < M.nonZeros(); ++s)
        M.valuePtr()[s] = part_hess[0][s] + part_hess[1][s];
      for (const auto& [s, v] : a_slots) M.valuePtr()[s] += mu * v;
      grad = mu * (A_full * y - b);
      for (int c = 0; c < n; ++c) grad(c) += part_grad[0][c] + part_grad[1][c];
      // M is SPD in exact arithmetic (μA plus PSD blocks); when the barrier's curvature
      // outgrows A's by many orders, rounding can break that: shift the diagonal and retry.
      bool factorized = false;
      for (int attempt = 0; attempt < 6 && !factorized; ++attempt) {
        try {
          solver.factorize(M);
          factorized = true;
        } catch (const SolverError&) {
          double shift = 0;
          for (int c = 0; c < n; ++c) shift = std::max(shift, M.valuePtr()[diag_slot[c]]);
          shift *= std::pow(10.0, -12 + 2 * attempt);
          for (int c = 0; c < n; ++c) M.valuePtr()[diag_slot[c]] += shift;
          ++rep.shifted_factorizations;
        }
      }
      if (!factorized) {
        broken = true;
        break;
      }
      ++rep.newton_steps;
      step = -solver.solve(grad);
      const double slope = grad.dot(step);
      if (!(slope < 0)) break;
      double t = 1.0, next = value;
      bool accepted = false;
      for (int ls = 0; ls < 30; ++ls, t *= 0.5) {
        trial = y + t * step;
        next = phi(trial, eps);
        if (std::isfinite(next) && next <= value + 1e-4 * t * slope) {
          accepted = true;
          break;
        }
      }
      if (!accepted) break;
      y = trial;
      moved = true;
      const double decrease = value - next;
      value = next;
      const int folds = foldovers(y);
      const double q = quadratic(y);
      if (folds < best_folds || (folds == best_folds && q < best_q)) {
        best = y;
        best_folds = folds;
        best_q = q;
        rep.epsilon = eps;
      }
      if (folds == 0) {
        rep.foldovers_after = 0;
        rep.time_s = elapsed();
        return y;
      }
      if (decrease <= 1e-6 * std::abs(value)) break;
    }
    // The next ε (the rule of Garanzha et al.): from how much this round lowered the barrier
    // (σ) and the smallest determinant, so that the most folded faces keep a finite, growing
    // pull towards positive area.
    const double barrier_after = barrier_sum(y, eps, &d_min);
    const double sigma = std::max(1 - barrier_after / barrier_before, o.min_sigma);
    const double target = (1 - sigma) * chi(d_min, eps);
    const double next_eps =
        d_min < target ? 2 * std::sqrt(target * (target - d_min)) : o.min_epsilon * det_scale;
    const double floor = o.min_epsilon * det_scale;
    if (broken || (!moved && eps <= floor)) break;
    eps = std::max(next_eps, floor);
  }
  rep.foldovers_after = best_folds;
  rep.time_s = elapsed();
  return best;
}

}  // namespace qs
