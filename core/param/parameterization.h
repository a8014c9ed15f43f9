// Global seamless parameterization whose base complex realizes the layout (paper §5;
// docs/design.md, "Parameterization"): energy (1) with anisotropic norm, node-connection
// constraints (3), iso-line constraints for boundary/pinned arcs and feature edges, all eliminated
// exactly.
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
#include "core/param/orientation.h"
#include "core/param/reduced_assembly.h"
#include "core/param/sizing.h"

namespace qs {

//! A prescribed parametric length of one arc (the `--integer` option, paper §8).
struct ArcLength {
  int arc_id = -1;    //!< LayoutArc::id
  double length = 0;  //!< signed, parameter units: the change of the arc's running coordinate
                      //!< (u or v) from its start node to its end node (ParamSolver::arc_lengths)
};

struct ParamOptions {
  //! Anisotropic norm (BZK09): misalignment is penalised `anisotropy` times more than scale.
  bool anisotropic = true;
  double anisotropy = 10.0;
  //! Per-face weights w_t multiplying each face's term of (1) (docs/design.md, "Stiffening").
  //! Empty (the default) means all 1; otherwise size #F, every entry > 0.
  std::vector<double> face_weights;
  //! Tri-sector orientation constraints when the solve has fold-overs (docs/design.md,
  //! "Orientation constraints").
  OrientationOptions orientation;
  //! Fixed arc lengths (integer patch sizes, paper §8): one linear row per listed arc, added to
  //! the node-connection constraints. Arcs not in the layout or dangling are ignored. Lengths
  //! that contradict each other (e.g. two opposite patch sides with different values) make the
  //! constraint set incompatible (InvalidInputError naming the arcs).
  std::vector<ArcLength> arc_lengths;
  //! Curl-reducing sizing field (paper §5.3, docs/design.md "Sizing field", sizing.h): the
  //! targets become e^{s_t} u_t, e^{s_t} v_t, with s recomputed from the field at every solve.
  SizingOptions sizing;
  //! Fill-reducing ordering of the reduced matrix from AMD on the wedge graph (one node per
  //! wedge's u, v unknowns; grouped_amd_ordering) instead of CHOLMOD's AMD on the full matrix.
  //! The analysis is cheaper, but the factor usually has more fill, so it is off
  //! (docs/benchmarks.md, "Design measurements").
  bool wedge_ordering = false;
  //! A fill-reducing order of the mesh's vertices (vertex_nested_dissection: entry k is the
  //! vertex eliminated k-th, size #V), or null. When set, a new reduced matrix's symbolic
  //! analysis takes its ordering from it (each unknown at its wedge's vertex, in that order; seam
  //! translations and the long columns of merged unknowns last) instead of AMD on the matrix.
  //! The vertex order does not depend on the layout: a Pipeline computes it once for all its
  //! solvers and the pipelines continued from it (PipelineOptions::order_vertices), as does the
  //! node optimizer on smaller meshes (optimize_nodes). Takes precedence over
  //! wedge_ordering.
  std::shared_ptr<const std::vector<int>> vertex_order;
  //! Runs independent parts of the stage on a second thread: the layout labels beside the cut
  //! graph (construction), and a symbolic analysis of the reduced matrix (a new pattern: a fresh
  //! solver, another layout) beside the energy assembly, which it cannot disturb: the analysis
  //! reads A's pattern only, fixed before the assembly. Same results; on two cores the stage
  //! waits for the longer part of each pair only.
  bool second_thread = true;
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
                      //!< ParamOptions::face_weights when they are set, with the sized targets
                      //!< when ParamOptions::sizing is enabled
  //! Per-face log-scale s_t of the targets (ParamOptions::sizing), size #F; empty when sizing
  //! is off (s = 0). The gradient estimator and face_energies take it with the corner values.
  std::vector<double> sizing_log_scale;
  int foldovers = 0;  //!< faces with signed parametric area ≤ 0
  //! The orientation-constrained solve, when ParamOptions::orientation is enabled and the
  //! unconstrained solution folds (its fold-over count is orientation.foldovers_before).
  OrientationReport orientation;
  // Diagnostics.
  int wedges = 0, cut_edges = 0, cut_curves = 0, constraint_rows = 0, eliminated = 0, redundant = 0,
      unknowns = 0;
  ParamTimings timings;
};

class ParamSolver {
 public:
  //! Builds the cut graph, labels, constraints and their elimination (combinatorial: they do not
  //! change when vertices move), then solves once. \p previous (optional): a solver built
  //! before for the same mesh connectivity (e.g. the node optimizer's last step); this solver
  //! swaps linear solvers with it, so CHOLMOD's symbolic analysis is reused when the reduced
  //! matrix has exactly the same sparsity pattern (unchanged combinatorics), and redone
  //! otherwise. \p previous stays usable (its next solve re-analyzes).
  //! \p solve_now false: no solve yet (result() is empty until the first solve()); the symbolic
  //! analysis starts (on the second thread, ParamOptions::second_thread) and the first
  //! factorization is the next solve()'s or optimal_field_rotation()'s. For a field whose
  //! rotation is still to be chosen, a first solve would be thrown away.
  //! \throw TopologyError, InfeasibleLayoutError (incompatible constraints naming arcs),
  //! SolverError.
  ParamSolver(const TriMesh& mesh, const GeometryCache& geometry, const Layout& layout,
              const LayoutTopology& topology, const std::vector<int>& period_jump,
              const std::vector<double>& theta, const ParamOptions& options = {},
              ParamSolver* previous = nullptr, bool solve_now = true);
  ~ParamSolver();

  //! For a solver built with \p solve_now false from a guess of the field (Pipeline: the
  //! previous step's θ, while the new field is solved): true when it is the solver a
  //! construction for \p period_jump and \p theta would build: the period jumps are these, and
  //! \p theta gives the same feature-edge directions and arc labels up to a half turn (the rows
  //! see a label's parity only), so every constraint row is the same. It then takes \p theta's
  //! labeling (symbols and diagnostics for \p theta). False: the solver is unchanged and not
  //! for this field. \p mesh, \p geometry, \p layout, \p topology: as at construction (same
  //! positions not required: the rows are combinatorial). \throw TopologyError as the constructor
  //! (labels).
  bool adopt_field(const TriMesh& mesh, const GeometryCache& geometry, const Layout& layout,
                   const LayoutTopology& topology, const std::vector<int>& period_jump,
                   const std::vector<double>& theta);

  //! Assembles the energy for the current geometry and field and solves; reuses the symbolic
  //! factorization.
  const Parameterization& solve(const TriMesh& mesh, const GeometryCache& geometry,
                                const std::vector<double>& theta);

  //! For a field whose global rotation is free (no direction constraints): the rotation φ
  //! (radians) to add to every θ_t that minimizes the isotropic energy (1) under this solver's
  //! constraints (with sizing: the sized targets; s does not depend on a global rotation). With
  //! homogeneous constraints E(φ) is a quadratic form in (cos φ, sin φ), so two extra
  //! back-substitutions give the exact optimum (φ in (−90°, 90°]). Prescribed arc lengths add terms
  //! linear in (cos φ, sin φ); a third back-substitution and a 1-D search over the whole circle
  //! then give the optimum (φ in (−180°, 180°]).
  double optimal_field_rotation(const TriMesh& mesh, const GeometryCache& geometry,
                                const std::vector<double>& theta);

  const Parameterization& result() const { return result_; }
  //! The signed parametric length of every arc with two end nodes, measured on the current
  //! result (same conventions as ParamOptions::arc_lengths), in layout arc order.
  std::vector<ArcLength> arc_lengths() const;
  const Labeling& labeling() const { return labeling_; }
  const CutGraph& cut_graph() const { return cut_; }
  const Reduction& reduction() const { return reduction_; }
  //! The CHOLMOD solver of the reduced system (its stats count analyses and factorizations).
  const SpdSolver& linear_solver() const { return solver_; }
  const ConstraintSystem& constraints() const { return system_; }

 private:
  ParamOptions options_;
  std::vector<int> period_jump_;
  CutGraph cut_;
  Labeling labeling_;
  ConstraintSystem system_;
  Reduction reduction_;
  ReducedAssembly assembly_;  //!< fixed patterns of H and A = ZᵀHZ (built with reduction_)
  //! Reads the upper triangle of A (ReducedAssembly stores both): SpdSolver::set_full_storage.
  SpdSolver solver_ = full_storage_solver("parameterization");
  //! The sizing field's solver (ParamOptions::sizing.enabled), built at the first solve.
  std::unique_ptr<SizingSolver> sizing_;
  Parameterization result_;
  //! e^{s_t} per face for \p theta (all 1 without sizing); stores s in result_.
  std::vector<double> target_scales(const TriMesh& mesh, const GeometryCache& geometry,
                                    const std::vector<double>& theta);
  //! Per arc with an end node: the running-coordinate difference end − start as an affine
  //! expression in the wedge unknowns (terms, constant).
  struct ArcSpan {
    int arc_id = -1;
    std::vector<std::pair<int, double>> terms;
    double constant = 0;
  };
  std::vector<ArcSpan> arc_spans_;
  //! The iso-line row of one Layout::feature_edges entry: the face whose chart it is written in
  //! (-1: no row, an arc edge or not a mesh edge) and whether it runs along u (v constant).
  struct FeatureRow {
    int face = -1;
    bool along_u = false;
    bool operator==(const FeatureRow& o) const { return face == o.face && along_u == o.along_u; }
    bool operator!=(const FeatureRow& o) const { return !(*this == o); }
  };
  //! Per Layout::feature_edges entry, from the field's θ at construction.
  std::vector<FeatureRow> feature_rows_;
  static std::vector<FeatureRow> feature_edge_rows(const TriMesh& mesh,
                                                   const GeometryCache& geometry,
                                                   const Layout& layout,
                                                   const std::vector<double>& theta);
  //! Hands the linear solver an ordering for its next analysis when \p A's pattern is not the
  //! analyzed one: ParamOptions::vertex_order expanded to A's unknowns, else with
  //! ParamOptions::wedge_ordering the wedge-graph ordering of A; else CHOLMOD chooses.
  void hint_ordering(const Eigen::SparseMatrix<double>& A);
  //! ParamOptions::vertex_order expanded to the unknowns of \p A (a permutation), or empty when
  //! it does not fit this mesh.
  std::vector<int> vertex_order_hint(const Eigen::SparseMatrix<double>& A) const;
  std::vector<int> wedge_vertex_;  //!< per wedge: its vertex (from the cut graph's corners)
  int n_vertices_ = 0;
  //! With ParamOptions::second_thread: starts the analysis of A's pattern on the second thread
  //! (SpdSolver::begin_analysis; a no-op for the analyzed pattern), hint included.
  void begin_analysis();
};

//! A nested-dissection order of \p geometry's vertices (their edge graph) for
//! ParamOptions::vertex_order; empty when METIS fails (the solvers then use AMD).
std::vector<int> vertex_nested_dissection(const GeometryCache& geometry);
//! The same for the graph of \p n_vertices vertices and the undirected \p edges (each once;
//! GeometryCache::edge_vertices), so that it can run apart from a GeometryCache that changes.
//! Empty when an edge names a vertex outside 0..n_vertices−1.
std::vector<int> vertex_nested_dissection(int n_vertices,
                                          const std::vector<std::array<int, 2>>& edges);

//! Energy (1) per face for given corner values (same conventions as the solver), without
//! ParamOptions::face_weights. \p log_scale: the targets' per-face log-scale s_t
//! (Parameterization::sizing_log_scale, size #F) or empty (s = 0). Size #F.
//! \throw InvalidInputError when log_scale is neither empty nor of size #F.
std::vector<double> face_energies(const TriMesh& mesh, const GeometryCache& geometry,
                                  const std::vector<double>& theta,
                                  const std::vector<std::array<double, 2>>& corner_uv,
                                  const ParamOptions& options = {},
                                  const std::vector<double>& log_scale = {});

//! Per reduced unknown (column of Reduction::Z; size \p free): its group for
//! grouped_amd_ordering: the unknowns that stand for the u and v variables (2w, 2w + 1) of one
//! wedge w share a group, every other one (seam translations) has its own. Groups are numbered
//! 0, 1, … in order of first appearance. \p free_index: Reduction::free_index.
std::vector<int> parameterization_groups(int wedges, const std::vector<int>& free_index, int free);

//! Signed parametric area (twice the area) of face f.
double param_signed_area2(const std::vector<std::array<double, 2>>& corner_uv, int f);

}  // namespace qs
