// Smoothest cross field with the layout's topology (paper §4.2; docs/design.md, "Cross field"):
// min Σ_e (θ_i + κ_ij + (π/2)p_ij − θ_j)² + λ Σ_{f∈C} (θ_f − c_f − (π/2)q_f)², with the
// period jumps p fixed by the layout and the integer constraint rotations q chosen per
// cluster. The matrix depends on neither geometry nor q: it is factorized once.
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/base/spd_solver.h"
#include "core/field/curvature.h"
#include "core/field/topology.h"

namespace qs {

//! How the integer rotations of the constraint clusters are initialized (docs/design.md, "Cross
//! field").
enum class ClusterWarmStart {
  //! Relax every cluster rotation to a real number, minimize the energy jointly with θ (the
  //! factorized field matrix plus one multi-right-hand-side solve, no extra factorization),
  //! then round each (MIQ-style relax-and-round).
  Relaxed,
  //! The smoothest field held only by the largest cluster (one extra factorization), every
  //! other cluster rounded against it.
  LargestCluster,
  //! Every cluster rounded against the smoothest field without direction constraints, pinned
  //! along the layout's longest arc: the field stays as close as possible to the layout's own
  //! directions, so no cluster twists it by quarter turns against the arcs (cage layouts that
  //! ignore curvature: issue #4 bunny). One extra factorization. Relaxed falls back to it
  //! above `max_relaxed_clusters` clusters.
  LayoutField,
};

//! What is released when the field contradicts the layout near an edge (see CrossFieldOptions).
enum class ConflictDrop {
  Clusters,  //!< every constraint cluster with a constrained face near a steep edge
  Faces,     //!< only the constrained faces near steep edges (experimental)
};

struct CrossFieldOptions {
  double constraint_weight = 100.0;  //!< λ, the paper's penalty factor
  //! How the field turns along boundary loops the layout leaves free (topology.h).
  FreeLoopTurning free_loops = FreeLoopTurning::kCap;
  ConstraintOptions constraints;
  int max_rounding_passes = 5;  //!< re-rounding of cluster rotations after each solve
  ClusterWarmStart warm_start = ClusterWarmStart::Relaxed;
  //! Above this many clusters (or 8M right-hand-side entries, #F per cluster) the relaxed warm
  //! start (one solve per cluster) falls back to LayoutField.
  int max_relaxed_clusters = 64;
  //! Constraint clusters that contradict the layout's topology (the solved field then jumps by
  //! more than 45° across some edge, i.e. its principal matching differs from the prescribed
  //! period jumps) are dropped: the nearest clusters within `conflict_rings` face rings of each
  //! such edge, for at most `max_conflict_passes` re-solves.
  int max_conflict_passes = 6;
  int conflict_rings = 6;
  ConflictDrop conflict_drop = ConflictDrop::Clusters;
  //! Split mode (> 0): the curvature constraints form clusters of at most this many faces,
  //! grown breadth-first, each with its own free quarter-turn rotation; the feature and
  //! boundary constraints keep whole clusters along their rings (which carry the angle across
  //! curvature-constrained faces too) and their conflicts are settled first, as in a run
  //! without curvature constraints (drop_structural_conflicts). 0 (default): one cluster per
  //! connected region of constrained faces of any kind.
  //! With whole regions one rotation must suit a region that crosses the layout's
  //! singularities, so the conflict passes release whole regions: cage layouts kept 0.2–13 %
  //! of their curvature constraints and the aligned run barely differed from --no-align. Split
  //! clusters are released only where they contradict the layout. At 10 the aligned E° falls
  //! below --no-align's on 14 of 16 test layouts (cage layouts, QuadWild and own quads, the
  //! conjugate-direction layout of inspired_mesh; a few % above it on two coarse animal cages),
  //! and the rocker-arm cage layout embeds only so (docs/benchmarks.md, "Design measurements").
  //! 0: whole regions.
  //! (`--max-cluster-faces`)
  int max_cluster_faces = 10;
  //! Split mode: a curvature cluster whose targets deviate from the layout's own field (the
  //! smoothest field with the layout's singularities, the warm start in split mode) by more
  //! than this mean angle (degrees, up to quarter turns; 45 at most) is released before the
  //! conflict passes. ≤ 0: off.
  double max_cluster_deviation_deg = 30.0;
};

//! Wall-clock seconds of the field stage's parts and operation counts (see bench/field_bench).
struct CrossFieldTimings {
  double curvature_s = 0;     //!< curvature tensor, reliable set and constraint collection
  double period_jumps_s = 0;  //!< exact integer period jumps from the layout
  double assemble_s = 0;      //!< constraint clusters and matrix assembly
  double factorize_s = 0;     //!< every CHOLMOD analysis + factorization of the setup
  double warm_start_s = 0;    //!< warm-start solve and cluster rounding (no factorization)
  double conflicts_s = 0;     //!< conflict checks and re-solves (no factorization)
  double solve_s = 0;         //!< last call of solve(): right-hand side, solves, rounding
  //! split mode: the ReferenceRotation callback (the Pipeline's: one parameterization setup
  //! and factorization), not part of warm_start_s
  double reference_rotation_s = 0;
  double setup_s = 0;      //!< whole constructor
  int factorizations = 0;  //!< numeric factorizations in the setup
  //! factorizations taken over from an earlier one of the same matrix instead (the structural
  //! pass's, CrossFieldSolver::drop_structural_conflicts)
  int reused_factorizations = 0;
  int solves = 0;           //!< back-substitutions (setup and re-solves)
  int rounding_passes = 0;  //!< extra solves after re-rounding cluster rotations (last solve)
  int conflict_passes = 0;  //!< re-solves after dropping contradicting clusters
};

struct CrossField {
  std::vector<double> theta;      //!< per face: angle of u_t from the frame r_t (radians), size #F
  std::vector<int> period_jump;   //!< per edge (canonical dual orientation), size #E
  FieldConstraints constraints;   //!< the direction constraints used
  std::vector<int> constraint_q;  //!< per constraint: integer quarter-turn offset
  //! Per constraint: 1 when in force, 0 when dropped as contradicting the layout's topology.
  std::vector<char> constraint_active;
  int clusters = 0;             //!< constraint clusters (each with one free rotation)
  int gauge_face = -1;          //!< face pinned when there are no constraints
  int dropped_clusters = 0;     //!< clusters dropped because they contradict the topology
  int dropped_constraints = 0;  //!< constrained faces in those clusters
  int active_constraints = 0;   //!< constrained faces still in force
  PeriodJumpReport topology;
  CrossFieldTimings timings;
};

//! Stateful solver: builds constraints, period jumps and the factorized matrix once. The
//! returned field is the smoothest one, except around edges where that one turns by more than
//! 45° against its period jump: there it is smoothed until its principal matching is the
//! period jumps (repair_matching), so its singularities are exactly the layout's. The
//! matrix depends on neither the geometry nor the period jumps, only on the set of active
//! constraints: `solve` after vertices moved and `update_layout` after nodes moved to other
//! vertices (new period jumps) only back-substitute with the existing factorization.
class CrossFieldSolver {
 public:
  //! Split mode (CrossFieldOptions::max_cluster_faces > 0): chooses the global rotation
  //! (radians, added to every θ) of the layout's own field, given that field's θ (per face,
  //! size #F) and the period jumps (per edge, size #E). The Pipeline passes the rotation that
  //! minimizes the parameterization energy (ParamSolver::optimal_field_rotation), the one a
  //! field without constraints gets.
  using ReferenceRotation =
      std::function<double(const std::vector<int>& period_jump, const std::vector<double>& theta)>;
  //! The period jumps of the layout being set up, with their report (update_layout).
  using PeriodJumpSource = std::function<std::vector<int>(PeriodJumpReport* report)>;

  //! \p reference_rotation (optional, split mode): see ReferenceRotation; called at most once,
  //! during construction, and not kept. Without it the layout's own field is pinned along one
  //! edge of the longest arc, which can lie 45° off the iso-lines (a diagonal of a triangulated
  //! quad mesh) and then releases the wrong curvature clusters.
  //! \throw TopologyError for layouts whose topology cannot be realized, SolverError.
  CrossFieldSolver(const TriMesh& mesh, const GeometryCache& geometry, const Layout& layout,
                   const LayoutTopology& topology, const CrossFieldOptions& options = {},
                   const ReferenceRotation& reference_rotation = {});
  ~CrossFieldSolver();
  //! A copy shares the factorizations (SpdSolver copies share them until one side factorizes):
  //! copying is O(#F), and a copy re-solved by update_layout or solve does no CHOLMOD analysis
  //! or factorization. The node optimizer gives each trial layout a copy of the current
  //! solver. Not for use from two threads at the same time.
  CrossFieldSolver(const CrossFieldSolver&) = default;
  CrossFieldSolver& operator=(const CrossFieldSolver&) = default;

  //! Solves for θ with the current geometry (reuses the factorization). \p geometry must be the
  //! construction's cache continued by update_geometry (same connectivity, κ continued), so that
  //! the period jumps stay valid. The constraint directions are the original 3D directions,
  //! projected onto the current faces. As after the constructor and update_layout, the field's
  //! principal matching is then repaired (repair_matching).
  const CrossField& solve(const GeometryCache& geometry);
  //! Interior edges where the smoothest field of the last constructor or set-up turned by more
  //! than 45° against its period jump after the conflict passes (before repair_matching): the
  //! mismatches update_layout's passes tolerate.
  int residual_mismatches() const { return residual_mismatches_; }
  //! After the layout changed on the same mesh connectivity (nodes moved to other vertices,
  //! arcs rerouted, vertices relocated): collects the constraints of the current geometry and
  //! layout as the constructor does (curvature recomputed). When they are on the same faces
  //! with the same kinds (only directions moved), it recomputes the period jumps and the
  //! clusters' relative rotations, puts every constraint back in force (the construction's
  //! factorization), redoes the warm start (relaxed mode; layout-field mode with its kept
  //! reference factorization) and re-solves; clusters that contradict the new layout are
  //! dropped as in the constructor (a factorization per drop pass, only when more edges
  //! mismatch than the constructor's passes left). Otherwise it sets up again as the
  //! constructor (one numeric factorization with the kept analysis, plus drop passes with the
  //! same tolerance). Either way the field is a fresh construction's at this geometry up to
  //! solver round-off, unless a drop pass that the tolerance skips would have helped, or (split
  //! mode) the construction chose the layout field's rotation (ReferenceRotation): the update
  //! keeps that rotation (fitted to the last reference) where a fresh construction would
  //! choose again, so the descent's field does not jump between steps.
  //! \throw TopologyError as the constructor, InvalidInputError when the mesh size changed.
  //! \p period_jumps (optional): supplies what compute_period_jumps(mesh, geometry, layout,
  //! topology, report) returns, e.g. computed on another thread (Pipeline); it may throw that
  //! function's errors.
  const CrossField& update_layout(const TriMesh& mesh, const GeometryCache& geometry,
                                  const Layout& layout, const LayoutTopology& topology,
                                  const PeriodJumpSource& period_jumps = {});
  const CrossField& field() const { return field_; }
  //! Gives every factorization shared with another copy of this solver its own CHOLMOD factor
  //! (numeric values included): the copies can then be solved on different threads.
  void unshare_solvers();
  //! Rotates the whole field by φ (radians) — meaningful only when it has no direction
  //! constraints (its global rotation is then free); later re-solves keep the rotation.
  void rotate(double phi);
  //! The curvature this solver computed for its constraints when it was computed from
  //! \p options at exactly \p mesh's vertex positions (same vertex count), else nullptr (curvature
  //! constraints off, other options, or positions moved since: solve() keeps the constraints).
  //! Bit-identical to compute_curvature(mesh, geometry, options) (update_curvature).
  const Curvature* curvature_at(const TriMesh& mesh, const CurvatureOptions& options) const;
  //! The field matrix currently factorized (dual-graph Laplacian + λ on active constraints).
  const Eigen::SparseMatrix<double>& matrix() const { return matrix_; }

 private:
  //! Curvature (when enabled; incremental from curvature_cache_) and collect_constraints for
  //! \p geometry and \p layout.
  FieldConstraints current_constraints(const TriMesh& mesh, const GeometryCache& geometry,
                                       const Layout& layout);
  //! The constructor after the constraints: period jumps, clusters, matrix, factorization
  //! (analysis reused on the same pattern), warm start, solve and drop passes.
  void setup(const TriMesh& mesh, const GeometryCache& geometry, const Layout& layout,
             const LayoutTopology& topology, FieldConstraints constraints, int tolerated = 0,
             const ReferenceRotation& reference_rotation = {},
             const PeriodJumpSource& period_jumps = {});
  Eigen::VectorXd rhs(const GeometryCache& geometry, const std::vector<double>& c) const;
  std::vector<double> constraint_angles(const GeometryCache& geometry) const;
  void factorize(SpdSolver& solver, const Eigen::SparseMatrix<double>& A);  //!< timed, counted
  Eigen::VectorXd back_substitute(const Eigen::VectorXd& b);
  //! Factorizes matrix_ into spare_ and makes it the current solver (the previous
  //! factorization stays in spare_).
  void factorize_as_current();
  //! factorize_as_current when solver_ does not factorize matrix_ (current_ false); keeps the
  //! factorization as full_ when every constraint is in force.
  void make_current();
  //! When no constraint is in force and no face is pinned: pins one face at its angle in
  //! \p theta (default: the last solved field).
  void pin_gauge_if_unconstrained(const Eigen::VectorXd* theta = nullptr);
  //! Marks the clusters with no constraint in force as dropped and counts them.
  void recount_dropped_clusters();
  //! Relative rotations inside each cluster by propagation over the carrier faces (needs p);
  //! on boundary loops that layout arcs cover, the ones the layout prescribes
  //! (aligned_boundary_turns).
  void propagate_clusters(const TriMesh& mesh, const GeometryCache& geometry, const Layout& layout,
                          const LayoutTopology& topology);
  //! Initial cluster offsets (see ClusterWarmStart); solver_ holds the factorization of matrix_.
  //! Without \p allow_factorization only the relaxed warm start runs (else offsets are kept).
  void warm_start(const GeometryCache& geometry, bool allow_factorization,
                  const ReferenceRotation& reference_rotation = {});
  //! Split mode: the global rotation (radians) to add to the layout's own field \p reference
  //! (pinned along the arc gauge): \p reference_rotation's when given (construction), else the
  //! best fit (up to quarter turns) to the last reference whose rotation was chosen so
  //! (rotation_anchor_: update_layout keeps the rotation as nodes move), else 0.
  double choose_reference_rotation(const Eigen::VectorXd& reference,
                                   const ReferenceRotation& reference_rotation);
  //! Each cluster's offset that best matches \p theta (per face) at its constraints in force;
  //! with \p only (per cluster) only the clusters it flags.
  void round_clusters(const std::vector<double>& c, const Eigen::VectorXd& theta,
                      const std::vector<char>* only = nullptr);
  //! arc_gauge_face_ and arc_gauge_angle_ for \p layout (-1 / 0 without arcs).
  void choose_arc_gauge(const TriMesh& mesh, const GeometryCache& geometry, const Layout& layout);
  //! Drop passes while more than \p tolerated edges mismatch (update_layout tolerates the
  //! ones the passes could not remove before). With \p curvature_only only curvature
  //! constraints are released (after the structural pass settled the others).
  void drop_conflicting_clusters(const TriMesh& mesh, const GeometryCache& geometry,
                                 int tolerated = 0, bool curvature_only = false);
  //! The common end of setup and update_layout: the structural pass (when it applies, with the
  //! warm start of the feature and boundary clusters inside it; the curvature clusters then
  //! start from the layout's own field), else the warm start; the deviation release, the solve
  //! and the conflict passes (curvature clusters only after a structural pass).
  void settle_and_warm_start(const TriMesh& mesh, const GeometryCache& geometry, int tolerated,
                             bool allow_factorization,
                             const ReferenceRotation& reference_rotation = {});
  //! Split mode (max_cluster_faces > 0): the warm start and the conflict passes for the
  //! feature and boundary clusters alone, as a run without curvature constraints does them
  //! (warm_start with \p allow_factorization and \p reference_rotation), before the curvature
  //! clusters come back into force (one factorization per pass; the next solve factorizes the
  //! matrix with the curvature constraints back, with no pass the full one). Otherwise
  //! the curvature clusters next to a feature or boundary cluster that contradicts the layout were
  //! released in its stead.
  //! update_layout starts the passes from the feature and boundary constraints the last pass
  //! dropped (structural_dropped_): they are dropped again at once, and passes run only while
  //! more edges mismatch than \p tolerated (on the 70K bunny 1730 of 1750 feature faces are
  //! dropped every descent step: one pass-free factorization instead of four to six).
  //! Returns whether the pass ran (structural_pass_applies).
  bool drop_structural_conflicts(const TriMesh& mesh, const GeometryCache& geometry, int tolerated,
                                 bool allow_factorization,
                                 const ReferenceRotation& reference_rotation = {});
  //! Whether drop_structural_conflicts runs its passes with every constraint in force.
  bool structural_pass_applies() const;
  //! Releases the curvature clusters that deviate from the layout's own field
  //! (CrossFieldOptions::max_cluster_deviation_deg). Only the matrix changes: the next solve
  //! factorizes it, once for the structural pass's drops and these releases together.
  void release_deviating_clusters(const GeometryCache& geometry);
  //! Interior edges whose principal matching differs from the period jump.
  int count_mismatches(const GeometryCache& geometry) const;
  //! The linear solve and cluster rounding of solve(), without the repair (the passes'
  //! solves, which judge the constraints by the smoothest field's mismatches).
  const CrossField& solve_system(const GeometryCache& geometry);
  //! The last step of every public solve: where the smoothest field turns by more than 45°
  //! across an edge against its period jump, θ is smoothed around that edge
  //! (repair_principal_matching; faces of constraints in force and the gauge face held), so the
  //! singularities measured on the field alone (field_quarter_indices) are the period jumps'
  //! (the layout's irregular nodes).
  void repair_matching(const GeometryCache& geometry);
  //! The energy the solve minimizes, at field_.theta: Σ over interior edges of the squared
  //! step against transport and period jump, plus λ·(θ_f − target)² on the constraints in force
  //! (current cluster offsets) and on the gauge face.
  double energy(const GeometryCache& geometry) const;

  CrossFieldOptions options_;
  //! The curvature of the last constraint collection (update_layout recomputes only around
  //! moved vertices).
  CurvatureCache curvature_cache_;
  CrossField field_;
  std::vector<int> constraint_at_;  //!< per face: constraint index or -1
  std::vector<char> carrier_;       //!< per face: carries the angle between constraints
  //! per face: on the ring of a feature or boundary constraint (a carrier for those kinds)
  std::vector<char> structural_carrier_;
  std::vector<int> cluster_size_;        //!< per cluster: constrained faces
  std::vector<int> cluster_of_;          //!< per constraint
  std::vector<int> relative_q_;          //!< per constraint, within its cluster
  std::vector<int> cluster_offset_;      //!< per cluster
  std::vector<char> cluster_active_;     //!< per cluster: 0 once dropped as contradictory
  std::vector<char> constraint_active_;  //!< per constraint: 0 once dropped
  bool active(int k) const { return cluster_active_[cluster_of_[k]] && constraint_active_[k]; }
  //! A curvature constraint (split mode: its clusters hold no other kind).
  bool is_curvature(int k) const { return field_.constraints.kind[k] == ConstraintKind::Curvature; }
  std::vector<Vec3> constraint_dir_;  //!< original 3D directions
  double gauge_angle_ = 0;
  int arc_gauge_face_ = -1;     //!< face along the middle of the longest arc
  double arc_gauge_angle_ = 0;  //!< that arc edge's angle in the face
  Eigen::SparseMatrix<double> matrix_;
  SpdSolver solver_{"cross field"};
  //! Whether solver_ factorizes matrix_ (solve() factorizes first when not: the structural
  //! pass and the deviation release only change the matrix).
  bool current_ = false;
  //! Second factorization of the same pattern (trial drops, largest-cluster warm start), so a
  //! rejected trial never needs a re-factorization; symbolic analysis reused between trials.
  SpdSolver spare_{"cross field"};
  //! Layout-field warm start: factorization of the matrix without direction constraints,
  //! pinned at reference_face_ (kept for update_layout).
  SpdSolver reference_{"cross field"};
  int reference_face_ = -1;
  //! The layout's own field of the last LayoutField warm start (empty otherwise), per face.
  Eigen::VectorXd reference_theta_;
  //! Split mode: the last layout field whose free rotation ReferenceRotation chose, or which
  //! continued such a one (empty before): update_layout keeps its rotation.
  Eigen::VectorXd rotation_anchor_;
  int residual_mismatches_ = 0;  //!< mismatching edges left by the constructor's drop passes
  //! The constructor's matrix and factorization with every constraint in force (before drop
  //! passes), and its gauge face: update_layout starts from them.
  //! full_ is factorized lazily in split mode: the structural pass replaces it unless it
  //! drops nothing (false while full_ holds an older matrix's factorization).
  Eigen::SparseMatrix<double> full_matrix_;
  SpdSolver full_{"cross field"};
  bool full_factorized_ = false;
  int full_gauge_face_ = -1;
  //! Per face: a feature or boundary constraint there was dropped by the last structural pass
  //! (empty before the first).
  std::vector<char> structural_dropped_;
  //! The last factorization of the structural pass (feature and boundary constraints only) and
  //! its matrix's values (same pattern as matrix_): the next pass with the same drops reuses it.
  SpdSolver structural_{"cross field"};
  std::vector<double> structural_values_;
};

//! What became of a field's direction constraints: how many faces each kind constrained and how
//! many of them are still in force after the constraint clusters that contradict the layout's
//! topology were released (CrossField::constraint_active). For reports and the editor.
struct ConstraintSummary {
  std::array<int, 3> constrained{};  //!< per ConstraintKind (curvature, feature, boundary)
  std::array<int, 3> in_force{};     //!< per ConstraintKind, of `constrained`
  int clusters = 0;
  int dropped_clusters = 0;  //!< clusters with no constraint in force
  int total_constrained() const { return constrained[0] + constrained[1] + constrained[2]; }
  int total_in_force() const { return in_force[0] + in_force[1] + in_force[2]; }
};

ConstraintSummary summarize_constraints(const CrossField& field);

//! A one-line warning when fewer than \p min_in_force (a fraction) of the constrained faces are
//! in force, e.g. "27 of 11114 constrained faces (0.2 %) are in force: the others contradict
//! the layout's topology and were released (11 of 12 constraint clusters), so the field follows
//! the layout rather than the curvature and features there (…)". Empty otherwise (also without
//! constraints).
std::string released_constraints_warning(const CrossField& field, double min_in_force = 0.5);

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
