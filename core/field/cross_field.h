// Smoothest cross field with the layout's topology (paper §4.2, algorithm.md §3):
// min Σ_e (θ_i + κ_ij + (π/2)p_ij − θ_j)² + λ Σ_{f∈C} (θ_f − c_f − (π/2)q_f)², with the
// period jumps p fixed by the layout and the integer constraint rotations q chosen per
// cluster. The matrix depends on neither geometry nor q: it is factorized once.
#pragma once

#include <memory>
#include <vector>

#include "core/base/spd_solver.h"
#include "core/field/curvature.h"
#include "core/field/topology.h"

namespace qs {

struct CrossFieldOptions {
  double constraint_weight = 100.0;  //!< λ, the paper's penalty factor
  ConstraintOptions constraints;
  int max_rounding_passes = 5;  //!< re-rounding of cluster rotations after each solve
  //! Constraint clusters that contradict the layout's topology (the solved field then jumps by
  //! more than 45° across some edge, i.e. its principal matching differs from the prescribed
  //! period jumps) are dropped: the nearest clusters within `conflict_rings` face rings of each
  //! such edge, for at most `max_conflict_passes` re-solves.
  int max_conflict_passes = 6;
  int conflict_rings = 6;
};

struct CrossFieldTimings {
  double curvature_s = 0, period_jumps_s = 0, assemble_s = 0, factorize_s = 0, solve_s = 0;
};

struct CrossField {
  std::vector<double> theta;      //!< per face: angle of u_t from the frame r_t (radians), size #F
  std::vector<int> period_jump;   //!< per edge (canonical dual orientation), size #E
  FieldConstraints constraints;   //!< the direction constraints used
  std::vector<int> constraint_q;  //!< per constraint: integer quarter-turn offset
  int clusters = 0;               //!< constraint clusters (each with one free rotation)
  int gauge_face = -1;            //!< face pinned when there are no constraints
  int dropped_clusters = 0;       //!< clusters dropped because they contradict the topology
  int dropped_constraints = 0;    //!< constrained faces in those clusters
  int active_constraints = 0;     //!< constrained faces still in force
  PeriodJumpReport topology;
  CrossFieldTimings timings;
};

//! Stateful solver: builds constraints, period jumps and the factorized matrix once; `solve`
//! can be called again after the geometry changed (κ, constraint angles), reusing the
//! factorization.
class CrossFieldSolver {
 public:
  //! \throw TopologyError for layouts whose topology cannot be realized, SolverError.
  CrossFieldSolver(const TriMesh& mesh, const GeometryCache& geometry, const Layout& layout,
                   const LayoutTopology& topology, const CrossFieldOptions& options = {});
  ~CrossFieldSolver();

  //! Solves for θ with the current geometry (reuses the factorization).
  const CrossField& solve(const GeometryCache& geometry);
  const CrossField& field() const { return field_; }
  //! Rotates the whole field by φ (radians) — meaningful only when it has no direction
  //! constraints (its global rotation is then free); later re-solves keep the rotation.
  void rotate(double phi);

 private:
  Eigen::VectorXd rhs(const GeometryCache& geometry, const std::vector<double>& c) const;
  void round_clusters(const GeometryCache& geometry, const std::vector<double>& c,
                      const Eigen::VectorXd& theta);

  CrossFieldOptions options_;
  CrossField field_;
  std::vector<int> cluster_of_;       //!< per constraint
  std::vector<int> relative_q_;       //!< per constraint, within its cluster
  std::vector<int> cluster_offset_;   //!< per cluster
  std::vector<char> cluster_active_;  //!< per cluster: 0 once dropped as contradictory
  std::vector<Vec3> constraint_dir_;  //!< original 3D directions
  Eigen::VectorXd gauge_angle_;
  SpdSolver solver_{"cross field"};
  bool solved_once_ = false;
};

//! Convenience: geometry + topology + one solve.
CrossField compute_cross_field(const TriMesh& mesh, const GeometryCache& geometry,
                               const Layout& layout, const LayoutTopology& topology,
                               const CrossFieldOptions& options = {});

//! Index of every interior vertex in quarter turns measured on the field alone (principal
//! matching across every edge + angle defect). Independent of the period jumps. Size #V.
std::vector<int> field_quarter_indices(const GeometryCache& geometry,
                                       const std::vector<double>& theta);

//! Principal matching per edge: round((θ_j − θ_i − κ_ij)/(π/2)); 0 on boundary edges.
std::vector<int> principal_matching(const GeometryCache& geometry,
                                    const std::vector<double>& theta);

//! First field direction per face (unit, in the face plane), size #F.
std::vector<Vec3> field_directions(const GeometryCache& geometry, const std::vector<double>& theta);

}  // namespace qs
