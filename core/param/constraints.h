// Linear equality constraints and their exact elimination by sparse Gaussian elimination
// (docs/design.md, "Solving"): x = Z y + z0, so the reduced energy stays SPD for CHOLMOD.
#pragma once

#include <Eigen/Sparse>
#include <string>
#include <utility>
#include <vector>

namespace qs {

struct LinearRow {
  std::vector<std::pair<int, double>> terms;  //!< (variable, coefficient)
  double rhs = 0;
  int origin = -1;  //!< index into ConstraintSystem::origins (what the row came from)
};

struct ConstraintSystem {
  int variables = 0;
  std::vector<LinearRow> rows;
  std::vector<std::string> origins;  //!< e.g. "seam at edge (4, 9)", "arc 7 (node connection)"
  //! Per variable (size `variables`, or empty = none): 1 for variables that appear in many
  //! reduced rows (the seam translations). They are pivots only of rows with no other
  //! candidate, and those rows are eliminated in a second, small pass whose result is
  //! substituted once at the end (substituting them row by row would touch every expression
  //! that uses them, many times).
  std::vector<char> eliminate_last;
  int add_origin(std::string s) {
    origins.push_back(std::move(s));
    return static_cast<int>(origins.size()) - 1;
  }
};

struct Reduction {
  Reduction() = default;
  Reduction(const Reduction&) = default;
  Reduction& operator=(const Reduction&) = default;
  //! Moves swap Z: Eigen 3.4.0's SparseMatrix has no move operations, so the implicit ones
  //! would copy it.
  Reduction(Reduction&& other) noexcept { *this = std::move(other); }
  Reduction& operator=(Reduction&& other) noexcept {
    Z.swap(other.Z);
    z0.swap(other.z0);
    free_index.swap(other.free_index);
    eliminated = other.eliminated;
    redundant = other.redundant;
    redundant_origins.swap(other.redundant_origins);
    return *this;
  }

  Eigen::SparseMatrix<double> Z;  //!< variables × free
  Eigen::VectorXd z0;             //!< size variables
  std::vector<int> free_index;    //!< per variable: column of Z, or -1 if eliminated
  int eliminated = 0;
  int redundant = 0;  //!< rows that reduced to 0 = 0
  std::vector<int> redundant_origins;
};

//! Eliminates all rows exactly: x = Z·y + z0 satisfies every row for every y, and every such x
//! is of this form. Pivots: the largest |coefficient| of the reduced row (ties, the usual case
//! with coefficients ±1, go to the variable used by the fewest eliminated expressions, i.e. a
//! Markowitz choice that keeps Z sparse and the elimination fast). Redundant rows (0 = 0 after
//! reduction) are counted and dropped. \throw InfeasibleLayoutError "incompatible constraints (k):
//! <origins>" naming every incompatible row's origin (e.g. "arc 7 (node connection)") when a
//! row reduces to 0 = c with |c| > tolerance·max(1, max |coefficient|); InvalidInputError when
//! a row names a variable outside [0, variables).
Reduction eliminate_constraints(const ConstraintSystem& system, double tolerance = 1e-9);

}  // namespace qs
