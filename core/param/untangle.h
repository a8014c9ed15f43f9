// Untangling a parameterization whose orientation constraints failed: a smooth barrier-like
// energy on the faces' Jacobians, minimized by Newton's method in the reduced unknowns, so that
// every equality constraint (seams, node connections, iso-lines) stays exact.
//
// The tri-sector constraints of orientation.h are a convex *inner* approximation of "every
// face positively oriented": when they are infeasible a fold-free map may still exist. It
// minimizes, for a decreasing sequence of ε > 0,
//
//   Φ_ε(y) = q(y) / q_scale + β · Σ_t a_t · F_ε(J_t),
//   F_ε(J) = ((1 − λ)·|J|²_F + λ·(D² + D0²)/D0) / χ(D, ε),   D = det J,
//   χ(D, ε) = (D + sqrt(ε² + D²)) / 2,
//
// q(y) = ½·yᵀA·y − bᵀy the parameterization's own (aligned) energy, q_scale the total area,
// a_t the face area, J_t the 2×2 Jacobian of (u, v) on face t in its tangent frame, and D0 the
// median det J of the start's unfolded faces. χ is a smooth positive stand-in for max(D, 0):
// for D ≫ ε, F_ε is the conformal distortion |J|²/D (≥ 2) and the area distortion D/D0 + D0/D
// (≥ 2) mixed; for D ≤ 0 it grows like |D|/ε², so as ε shrinks folded faces are pushed to
// positive area, while q keeps the map aligned with the field. The area term stops a face from
// escaping the barrier by collapsing (J → 0), which the conformal term alone allows. This is the
// regularized untangling of Garanzha, Kaporin, Kudryavtseva, Protais, Ray and Sokolov
// ("Foldover-free maps in 50 lines of code", 2021) with the field-aligned energy added, written
// from the paper's formulas, including its rule for the next ε (from the barrier's relative
// decrease σ ≥ min_sigma and the smallest determinant). Each Newton step factorizes q's matrix plus
// the per-face Hessians projected onto positive semidefinite ones (eigenvalues clamped), by CHOLMOD
// with one symbolic analysis for the whole run, and a backtracking line search on Φ_ε follows.
//
// The map is returned as soon as it has no fold-over; otherwise the iterate with the fewest
// fold-overs (ties: the lowest q) is returned when the ε rule or the step budget runs out.
#pragma once

#include <Eigen/Sparse>
#include <string>
#include <vector>

#include "core/base/progress.h"
#include "core/mesh/geometry.h"
#include "core/param/constraints.h"

namespace qs {

struct UntangleOptions {
  double beta = 0.05;  //!< weight β of the barrier term against q (both per area)
  //! λ: the weight of the area term in F_ε (Garanzha et al. mix the two halves too)
  double area_weight = 0.5;
  double initial_epsilon = 1.0;  //!< ε of the first round, relative to D0
  double min_epsilon = 1e-8;     //!< lower bound of ε, relative to D0
  //! σ ≥ min_sigma in the ε rule (0.1 in Garanzha et al.; larger values let ε shrink while
  //! faces are still folded)
  double min_sigma = 0.2;
  //! Newton steps per ε at most (a round also ends when Φ_ε stops decreasing). Too few let ε
  //! shrink faster than the folded faces open; too many spend the budget on early rounds.
  int newton_per_round = 5;
  //! Newton steps in all at most (one factorization each)
  int max_newton = 600;
  //! Evaluate the faces' barrier terms (gradients, projected Hessians, energies) on two
  //! threads, half of the faces each, when the machine has two cores. The result is the same
  //! either way (the halves always sum separately). Used from 8000 faces on.
  bool second_thread = true;
  //! Polled before every Newton step (throws qs::Cancelled); not owned, may be nullptr.
  const Observer* observer = nullptr;
};

struct UntangleReport {
  bool ran = false;
  int foldovers_before = 0, foldovers_after = 0;
  int rounds = 0;        //!< ε values used
  int newton_steps = 0;  //!< factorizations
  //! factorizations repeated with a shifted diagonal (rounding lost positive definiteness)
  int shifted_factorizations = 0;
  double epsilon = 0;  //!< ε of the returned iterate's round
  double time_s = 0;
};

//! Minimizes Φ_ε above from \p y_start (reduced unknowns; x = Z·y + z0 holds 2 values (u, v)
//! per wedge, \p corner_wedge the wedge of each face corner, size 3·#F). \p A (SPD, at least its
//! lower triangle) and \p b define q. Uses the geometry's cached hat-function gradients
//! (GeometryCache::face_gradient; refused without them). Returns the first iterate without
//! fold-overs, else the one with the fewest.
Eigen::VectorXd untangle(const GeometryCache& geometry, const std::vector<int>& corner_wedge,
                         const Reduction& reduction, const Eigen::SparseMatrix<double>& A,
                         const Eigen::VectorXd& b, const Eigen::VectorXd& y_start,
                         const UntangleOptions& options, UntangleReport* report = nullptr);

}  // namespace qs
