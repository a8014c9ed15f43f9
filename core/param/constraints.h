// Linear equality constraints and their exact elimination by sparse Gaussian elimination
// (algorithm.md §4.6): x = Z y + z0, so the reduced energy stays SPD for CHOLMOD.
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
  int add_origin(std::string s) {
    origins.push_back(std::move(s));
    return static_cast<int>(origins.size()) - 1;
  }
};

struct Reduction {
  Eigen::SparseMatrix<double> Z;  //!< variables × free
  Eigen::VectorXd z0;             //!< size variables
  std::vector<int> free_index;    //!< per variable: column of Z, or -1 if eliminated
  int eliminated = 0;
  int redundant = 0;  //!< rows that reduced to 0 = 0
  std::vector<int> redundant_origins;
};

//! Eliminates all rows exactly. Redundant rows (0 = 0 after reduction) are counted and
//! dropped. \throw InvalidInputError naming the incompatible rows' origins when a row reduces to
//! 0 = c with |c| > tolerance.
Reduction eliminate_constraints(const ConstraintSystem& system, double tolerance = 1e-9);

}  // namespace qs
