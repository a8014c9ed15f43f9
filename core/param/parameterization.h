// Global seamless parameterization whose base complex realizes the layout (paper §5,
// algorithm.md §4): energy (1) with anisotropic norm, node-connection constraints (3),
// iso-line constraints for boundary/pinned arcs and feature edges, all eliminated exactly.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "core/base/spd_solver.h"
#include "core/layout/layout.h"
#include "core/mesh/geometry.h"
#include "core/param/constraints.h"
#include "core/param/cut_graph.h"
#include "core/param/labeling.h"

namespace qs {

struct ParamOptions {
  //! Anisotropic norm (BZK09): misalignment is penalised `anisotropy` times more than scale.
  bool anisotropic = true;
  double anisotropy = 10.0;
  //! Per-face weights w_t multiplying each face's term of (1) (stiffening, algorithm.md §7.1).
  //! Empty (the default) means all 1; otherwise size #F, every entry > 0.
  std::vector<double> face_weights;
};

struct ParamTimings {
  double setup_s = 0;      //!< cut graph, labelling, constraint rows, elimination (once)
  double assemble_s = 0;   //!< energy matrix and reduction ZᵀHZ (each solve)
  double factorize_s = 0;  //!< CHOLMOD numeric factorization (each solve)
  double analyze_s = 0;    //!< CHOLMOD symbolic analysis (once)
  double solve_s = 0;      //!< back-substitution and corner values (each solve)
};

struct Parameterization {
  //! (u, v) per face corner, size 3·#F, corner k of face f at 3f + k (GeometryCache order).
  std::vector<std::array<double, 2>> corner_uv;
  double energy = 0;  //!< E: value of energy (1) at the solution (length² units), weighted by
                      //!< ParamOptions::face_weights when they are set
  int foldovers = 0;  //!< faces with signed parametric area ≤ 0
  // Diagnostics.
  int wedges = 0, cut_edges = 0, cut_curves = 0, constraint_rows = 0, eliminated = 0, redundant = 0, unknowns = 0;
  ParamTimings timings;
};

class ParamSolver {
 public:
  //! Builds the cut graph, labels, constraints and their elimination (combinatorial: they do not
  //! change when vertices move). \throw TopologyError, InvalidInputError (incompatible
  //! constraints naming arcs), SolverError.
  ParamSolver(const TriMesh& mesh, const GeometryCache& geometry, const Layout& layout,
              const LayoutTopology& topology, const std::vector<int>& period_jump,
              const std::vector<double>& theta, const ParamOptions& options = {});
  ~ParamSolver();

  //! Assembles the energy for the current geometry and field and solves; reuses the symbolic
  //! factorization.
  const Parameterization& solve(const TriMesh& mesh, const GeometryCache& geometry,
                                const std::vector<double>& theta);

  //! For a field whose global rotation is free (no direction constraints): the rotation φ
  //! (radians) to add to every θ_t that minimizes the isotropic energy (1) under this solver's
  //! constraints. E(φ) is a quadratic form in (cos φ, sin φ) because the constraints are
  //! homogeneous, so two extra back-substitutions give the exact optimum.
  double optimal_field_rotation(const TriMesh& mesh, const GeometryCache& geometry,
                                const std::vector<double>& theta);

  const Parameterization& result() const { return result_; }
  const Labeling& labeling() const { return labeling_; }
  const CutGraph& cut_graph() const { return cut_; }
  const Reduction& reduction() const { return reduction_; }
  const ConstraintSystem& constraints() const { return system_; }

 private:
  ParamOptions options_;
  std::vector<int> period_jump_;
  CutGraph cut_;
  Labeling labeling_;
  ConstraintSystem system_;
  Reduction reduction_;
  SpdSolver solver_{"parameterization"};
  Parameterization result_;
};

//! Energy (1) per face for given corner values (same conventions as the solver). Size #F.
std::vector<double> face_energies(const TriMesh& mesh, const GeometryCache& geometry,
                                  const std::vector<double>& theta,
                                  const std::vector<std::array<double, 2>>& corner_uv,
                                  const ParamOptions& options = {});

//! Signed parametric area (twice the area) of face f.
double param_signed_area2(const std::vector<std::array<double, 2>>& corner_uv, int f);

}  // namespace qs
