// Strict orientation constraints for the parameterization (paper §6.3 "Limitations of Node
// Movement"; docs/design.md, "Orientation constraints"): linear tri-sector constraints [BCE*13] on
// the faces that fold, solved as a convex QP in the reduced unknowns by a primal-dual
// interior-point method whose Newton systems are factorized by CHOLMOD (no extra dependency).
//
// Problem. The parameterization solve eliminates every equality constraint exactly:
// x = Z·y + z0 (x: 2 values (u, v) per wedge, y: the free unknowns), and minimizes
// ½·yᵀA·y − bᵀy with A = ZᵀHZ SPD. Here we add, for a set S of faces,
//
//   min ½·yᵀA·y − bᵀy   subject to   C·y ≥ d,
//
// so the equality constraints (seams, node connections, iso-lines) stay satisfied exactly.
//
// Tri-sector constraints of face t. Let P_0, P_1, P_2 be its corners in (u, v) (affine in y)
// and c = (P_0 + P_1 + P_2)/3 their centroid; D_k = P_k − c. The "ideal" offsets Q_k are the
// 3D corner offsets from the 3D centroid expressed in the field frame (u_t, v_t) of the face —
// exactly the images under the map the energy (1) aims for (∇u = u_t, ∇v = v_t, a rotation).
// Let ρ_k be the unit bisector of the (unit) directions of Q_{k−1} and Q_k (indices mod 3).
// Sector k is the open cone from ρ_k counter-clockwise to ρ_{k+1}; it contains Q_k and is
// narrower than π because, for a non-degenerate ccw triangle, consecutive Q's are less than π
// apart. The six linear constraints (× is the 2D cross product a×b = a_x b_y − a_y b_x)
//
//   ρ_k × D_k ≥ ε_t   and   D_k × ρ_{k+1} ≥ ε_t        (k = 0, 1, 2)
//
// put each D_k strictly inside sector k. Proof that the face is then positively oriented:
// D_0 + D_1 + D_2 = 0 and the D_k are non-zero, in three disjoint sectors in ccw order, so the
// ccw angles between consecutive D_k are positive and add up to 2π. If one were ≥ π the three
// vectors would lie in a closed half-plane; summing to zero they would then be collinear on its
// boundary line, putting two of them in the same direction, i.e. in the same sector — a
// contradiction. So each consecutive pair has D_k × D_{k+1} > 0, and twice the signed area
// (P_1 − P_0) × (P_2 − P_0) = D_0×D_1 + D_1×D_2 + D_2×D_0 > 0. The margin ε_t = margin · h_t
// (h_t: the face's mean edge length; (u, v) are in length units) keeps the face away from
// degeneracy. Constraints are only a sufficient (inner, convex) condition for orientation.
//
// Two solvers, same optimum. Few constraints (m ≤ dense_max_rows rows and m·#y small): the dual
// QP in the multipliers λ ≥ 0 — min ½λᵀSλ + gᵀλ with S = C·A⁻¹·Cᵀ, g = C·y0 − d, and
// y = y0 + A⁻¹Cᵀλ — is dense and small; A⁻¹Cᵀ costs m back-substitutions with the
// factorization the parameterization already has, and each interior-point iteration only a
// dense m×m Cholesky (chosen when that is cheaper than a sparse factorization). Otherwise: the
// primal problem, each iteration factorizing A + Cᵀdiag(λ/s)C with CHOLMOD (one symbolic analysis
// per active set).
//
// Sector frame (OrientationOptions::sector_frame). The rays need not come from the field frame:
// any three sectors in ccw order, each narrower than π, make the condition above sufficient.
// The solution frame turns each face's Q_k by the rotation closest to the unconstrained
// solution's Jacobian on that face (its polar factor; folded and degenerate faces take the mean
// rotation of their neighbours, ring by ring), by at most 45° from the field frame, so the
// sectors sit nearer to where the solution puts the corners while keeping the field's winding
// around every vertex. Where the layout makes the map turn away from the field (arcs that leave
// the field's directions near crowded nodes), field-frame sectors ask each face to turn back,
// which together with the iso-line constraints can be infeasible. Neither frame's feasible set
// contains the other's, so by default the field frame is solved first and, only where
// fold-overs remain, the solution frame as well; the solution with fewer fold-overs is kept and
// the report's counts and time cover both attempts.
//
// Active set. Only faces that need it are constrained: the folded faces of the unconstrained
// solution and `rings` rings of neighbours around them; when the constrained solution folds
// other faces, those (and their rings) are added and the QP re-solved (at most max_rounds).
#pragma once

#include <Eigen/Sparse>
#include <array>
#include <string>
#include <vector>

#include "core/base/progress.h"
#include "core/base/spd_solver.h"
#include "core/mesh/geometry.h"
#include "core/mesh/mesh.h"
#include "core/param/constraints.h"
#include "core/param/untangle.h"

namespace qs {

//! Which frame the tri-sector rays are built in (see "Sector frame" above).
enum class SectorFrame {
  kField,     //!< the field frame (u_t, v_t) of each face
  kSolution,  //!< the field frame turned by the unconstrained solution's rotation on the face
  kFieldThenSolution,  //!< kField; where fold-overs remain, kSolution too; fewer fold-overs kept
};

struct OrientationOptions {
  //! Apply the constraints in the parameterization solve when it has fold-overs
  //! (ParamOptions::orientation; the node optimizer enables it for its last solve).
  bool enabled = false;
  SectorFrame sector_frame = SectorFrame::kFieldThenSolution;  //!< frame of the tri-sector rays
  int rings = 2;            //!< neighbour rings (across edges) added around each folded face
  int max_rounds = 5;       //!< active-set growth rounds (QP solves) at most
  int max_iterations = 60;  //!< interior-point iterations per QP at most (one factorization each)
  double margin = 1e-3;     //!< ε_t = margin · (mean edge length of face t)
  double tolerance = 1e-9;  //!< on the scaled primal residual, dual residual and complementarity
  //! The dense dual solver is used up to this many constraint rows (6 per constrained face)
  //! and while rows × unknowns ≤ dense_max_entries (memory of A⁻¹Cᵀ); 0 disables it.
  int dense_max_rows = 900;
  double dense_max_entries = 2e7;
  //! … and while m³ ≤ dense_cost_ratio · #y^1.5: a dense m×m Cholesky per iteration must stay
  //! cheaper than a sparse factorization (≈ #y^1.5 for surface meshes). Deterministic choice.
  double dense_cost_ratio = 100.0;
  //! After this many rounds solved by the sparse (primal) solver that left fold-overs outside
  //! their set, the next round constrains every face instead of growing the set (0: never).
  //! The primal solver factorizes a matrix of A's size in each iteration however many rows
  //! there are, and on large models growing rounds keep finding new fold-overs just outside
  //! the set. Constraining every face also binds faces that would not fold (a higher E), hence
  //! not after the first round. If the all-faces round is infeasible (the constraints are only
  //! sufficient for orientation), the growing rounds go on.
  int all_faces_after_rounds = 2;
  //! When the all-faces round is infeasible, stop there with the best earlier round instead of
  //! growing the set further. The node optimizer sets it where it has an earlier state to fall
  //! back to: the further rounds rarely remove every fold-over there, and the earlier state's
  //! solve decides anyway.
  bool stop_if_all_faces_infeasible = false;
  //! Polled before every round and every interior-point iteration (throws qs::Cancelled when it
  //! asks to cancel): one solve can run for seconds on large models. Not owned; must outlive the
  //! solve; nullptr: never cancelled.
  const Observer* observer = nullptr;
  //! Where fold-overs remain after the QP (or it is infeasible), minimize the untangling
  //! energy of untangle.h from the better of the two solutions; kept when it has fewer
  //! fold-overs. The tri-sector constraints are only sufficient for orientation, so a map they
  //! cannot reach may still unfold.
  bool untangle = true;
  UntangleOptions untangle_options;  //!< its observer is \ref observer
};

struct OrientationReport {
  bool ran = false;  //!< fold-overs were present and the constrained QP was attempted
  //! The result was used: it has fewer fold-overs than before (set by ParamSolver::solve).
  bool success = false;
  int foldovers_before = 0, foldovers_after = 0;
  int constrained_faces = 0;      //!< |S| in the last round
  int skipped_faces = 0;          //!< faces of S left out: degenerate 3D triangle
  bool all_faces = false;         //!< the last round constrained every face
  int rounds = 0;                 //!< QP solves
  int iterations = 0;             //!< interior-point iterations in total
  int sparse_factorizations = 0;  //!< CHOLMOD factorizations (primal solver only)
  //! Factorizations of the primal solver repeated with a lower clamp of λ/s because rounding
  //! made the normal matrix lose positive definiteness (no error then, see orientation.cpp).
  int clamp_reductions = 0;
  //! sparse rounds whose normal matrices took the given ordering (solve_oriented's \p ordering)
  int ordered_rounds = 0;
  bool dense = false;                          //!< the last round used the dense dual solver
  double energy_before = 0, energy_after = 0;  //!< value of the (weighted) energy (1)
  double time_s = 0;
  //! The frame of the sectors of the returned solution (kField or kSolution).
  SectorFrame sector_frame = SectorFrame::kField;
  std::string message;  //!< why it failed, if it did
  //! When the last round was infeasible: the constrained faces its last iterate violates most
  //! (at most 5, worst first; also named in \ref message), where the layout cannot unfold.
  std::vector<int> infeasible_faces;
  UntangleReport untangle;  //!< the untangling after the QP (OrientationOptions::untangle)
};

//! Per-face ideal corner offsets Q_k (see above) in the field frame, [f][k] = (u, v), length
//! units; all zero for a degenerate face. Size #F.
std::vector<std::array<std::array<double, 2>, 3>> ideal_corner_offsets(
    const TriMesh& mesh, const GeometryCache& geometry, const std::vector<double>& theta);

//! Frame angles (radians, per face, size #F) for ideal_corner_offsets that turn each face's
//! field frame \p theta by the rotation closest to the map \p x on it (x: 2 values (u, v) per
//! wedge; \p corner_wedge: size 3·#F): for a map that is a rotation times a scale on a face,
//! the face's Q_k are then parallel to its corner offsets. Faces the map folds or collapses
//! take the mean rotation of their neighbours across edges, ring by ring; a connected
//! component without any unfolded face keeps \p theta. Uses the geometry's cached hat-function
//! gradients (\ref GeometryCache::face_gradient; refused without them).
std::vector<double> solution_frame_angles(const GeometryCache& geometry,
                                          const std::vector<double>& theta,
                                          const std::vector<int>& corner_wedge,
                                          const Eigen::VectorXd& x);

//! Solves the QP above starting from the unconstrained minimizer \p y0 (A·y0 = b).
//! \p factorized_A, when given, holds a factorization of A (enables the dense dual solver).
//! \p corner_wedge: wedge of each face corner (size 3·#F; wedge w owns x(2w), x(2w+1)).
//! Returns the reduced unknowns y of the constrained optimum, with every constrained face
//! positively oriented; report->foldovers_after counts fold-overs over all faces.
//! \throw SolverError when the constraints are infeasible for this layout and field (e.g. a
//! node of very high valence, faces that the equality constraints force to fold) in the first
//! round. When a later round (a grown set) is infeasible, the earlier round with the fewest
//! fold-overs is returned and report->message says so.
//! \p ordering, when given and not empty: the fill-reducing ordering of y's unknowns for the
//! sparse rounds' normal matrices (a permutation, SpdSolver::set_ordering_hint; the
//! parameterization passes its ParamOptions::vertex_order expanded), instead of AMD per round.
Eigen::VectorXd solve_oriented(const TriMesh& mesh, const GeometryCache& geometry,
                               const std::vector<double>& theta,
                               const std::vector<int>& corner_wedge, const Reduction& reduction,
                               const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& b,
                               const Eigen::VectorXd& y0, const OrientationOptions& options,
                               OrientationReport* report = nullptr,
                               SpdSolver* factorized_A = nullptr,
                               const std::vector<int>* ordering = nullptr);

//! Fold-overs (signed parametric area ≤ 0) of x = Z·y + z0. Size-#F flags in \p folded if given.
int count_foldovers(const std::vector<int>& corner_wedge, const Eigen::VectorXd& x,
                    std::vector<char>* folded = nullptr);

}  // namespace qs
