// Node optimization by gradient descent on the residual E of energy (1) (paper §6.1, §7;
// docs/design.md, "Node optimization"): alternating (A) field + parameterization solves with fixed
// nodes and (B) a step of all unpinned nodes along −∇E, traced as straightest geodesics and
// realized by relocating one mesh vertex per node; steps that raise E are undone and α halved.
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "core/base/progress.h"
#include "core/layout/layout.h"
#include "core/layout/node_shift.h"
#include "core/mesh/mesh.h"
#include "core/nodeopt/gradient.h"
#include "core/nodeopt/relocation.h"
#include "core/nodeopt/stiffening.h"
#include "core/pipeline/pipeline.h"

namespace qs {

enum class GradientMethod { Estimator, Exact };

struct NodeSymmetry;  // core/nodeopt/symmetric_step.h

//! Settings that only tests and benchmarks change, to force or compare a mechanism; the
//! defaults are the tuned ones, and neither the engine nor the command line maps them. Lengths
//! relative to the mean edge length.
struct NodeOptTuning {
  // ---- descent (docs/design.md, "Step length") ----
  //! A descent phase also ends (as when its budget is used up: the hop sweep follows) after
  //! stall_steps accepted steps in a row that each lowered E by less than stall_gain (relative).
  //! ≤ 0: off, the paper's rule (the budget, the halvings or convergence). Off by default:
  //! ending phases early can leave states whose orientation constraints are infeasible.
  double stall_gain = 0;
  int stall_steps = 2;
  //! After a sweep with hops the descent restarts at min(alpha, hop_alpha_growth × the α of the
  //! phase's last accepted step) instead of alpha (≤ 0: at alpha), since hops change where the
  //! nodes sit, not the step sizes that fit.
  double hop_alpha_growth = 2.0;
  //! A trial whose switches are mostly (at least half of them: the same node to the same
  //! vertex) those of the last trial rejected at the current α is rejected without a solve, and
  //! the retry without switches follows: at an unchanged α the descent would otherwise propose
  //! and solve the same rejected switches again.
  bool switch_tabu = true;

  // ---- hop polish (docs/design.md, "Hop polish") ----
  int max_hop_rounds = 3;      //!< hop sweeps at most (each after a converged descent)
  int hop_descent_steps = 10;  //!< descent steps available at least after a sweep with hops
  //! Only nodes whose vertex is relocated at least this fraction of the mean edge length off
  //! its original position try to hop to a neighbour (0: every relocated node).
  double hop_min_offset = 0;
  int hop_candidates = 2;    //!< neighbours tried per node (best aligned first)
  double hop_min_cos = 0.0;  //!< only neighbours within 90° of the relocation direction
  //! Candidate solves per sweep for the neighbour hops (work cap); the most strained nodes
  //! (largest relocation) try first.
  int hop_max_evaluations = 64;
  //! The neighbour hops stop after this many solves in a row without a lower E (≤ 0: no
  //! limit), so that large models do not spend the budget without gain.
  int hop_max_failures = 16;
  //! Each sweep first tries, as one solve, all relocations undone at once together with the
  //! cone hops below (a node on the right vertex only helps when its neighbours are too).
  bool hop_collective = true;
  //! Then the sharp cone vertices (discrete.h cone_candidates), one node at a time: a node of
  //! valence ≠ 4 relocated off a vertex whose angle deficit fits its index tries that vertex at
  //! its original position, and a node on a vertex that does not fit tries the fitting free
  //! vertices within hop_cone_rings rings. The descent cannot reach them (it never puts a node
  //! exactly on a vertex's original point, and a relocated cone vertex loses its cone). On
  //! smooth meshes no vertex fits and these passes do nothing.
  bool hop_cones = true;
  int hop_cone_rings = 2;         //!< search radius around the node's vertex (rings)
  int hop_cone_targets = 2;       //!< fitting vertices tried per node (nearest first)
  int hop_cone_max_failures = 8;  //!< as hop_max_failures, for each cone pass

  // ---- fold-over removal (docs/design.md, "Fold-over removal") ----
  //! The last fallback of the fold-over removal (with folds.orientation): when fold-overs
  //! remain at the final state and at the earlier states tried (before the polish, the fewest
  //! fold-overs), the initial state gets the orientation constraints too and is returned when
  //! it ends with fewer fold-overs (NodeOptResult::initial_reverted): a layout that embeds where
  //! the user put its nodes is not handed back folded.
  bool initial_fallback = true;
  //! For diagnostics and the fallback's tests: false skips the orientation-constrained solve at
  //! every state whose nodes or vertices moved (the final state, before the polish, the fewest
  //! fold-overs), as if it had left their fold-overs, so that only the initial state's solve
  //! (initial_fallback) can remove them. This shows whether the sketch itself embeds, and
  //! exercises the fallback chain on any input and CPU. Stiffening still runs where fold-overs
  //! remain.
  bool orientation_at_moved_states = true;
  StiffeningOptions stiffening;  //!< of folds.stiffen
};

//! Settings of the node optimization (docs/design.md, "Node optimization"), in groups. Lengths
//! relative to the mean edge length unless stated. The orientation-constrained solves of the
//! fold-over removal take their OrientationOptions (sector frame, untangling, limits) from the
//! PipelineOptions::param.orientation given to the optimizer (its `enabled` aside).
struct NodeOptOptions {
  //! The gradient descent (docs/design.md, "Step length"). A descent phase ends when no node
  //! moves (every step shorter than 10⁻⁴ mean edge lengths), after more than 5 halvings of α,
  //! or when its step budget is used up. Each node's trace stays in its Dijkstra-Voronoi cell
  //! (docs/design.md, "Straightest geodesics"). A step that raises E after some nodes changed
  //! their vertex is retried once with those nodes kept on their vertices before α is halved
  //! ("Retries"); a sliding node whose switch raised E takes half steps from then on, until a
  //! switch of its own is accepted or a hop sweep starts a new phase (otherwise a node sliding
  //! along the boundary and an interior node lined up with it can propose the same swap at
  //! every step).
  struct Descent {
    //! Descent steps (accepted + rejected) before the first hop sweep; a sweep that moves nodes
    //! extends the budget to at least tuning.hop_descent_steps more.
    int max_steps = 25;
    //! Damping factor α of the step length l = α · s · ‖d‖, s = ⅔ for the estimator and 1 for
    //! the exact gradient (paper §7.2). A rejected step (E rose) halves α.
    double alpha = 0.75;
    GradientMethod gradient = GradientMethod::Estimator;
  } descent;

  //! Where and how nodes move (docs/design.md, "Node relocation").
  struct Moves {
    //! Nodes on a feature curve (the layout's feature edges) or on the mesh boundary slide along
    //! it (paper §6.1.1): the descent direction projected onto the curve, the walk restricted to
    //! it, the node's vertex relocated along the curve segment, the arcs along the curve moved
    //! with the node. A node where the curve ends, branches or turns by more than 30° stays (as
    //! do all such nodes when false). No other node relocates a vertex on these curves; a step
    //! ending within half an edge of one takes the node onto it, unmoved. In hop sweeps a
    //! sliding node tries only the curve neighbour its relocation leans to (and the cone passes,
    //! off the boundary).
    bool slide_on_curves = true;
    //! The sharp edges (at the field's sharp angle) count as feature curves too: nodes on them
    //! slide along them, and no node relocates a vertex on them, so they keep their shape at a
    //! higher E. Off by default: on coarse organic meshes many edges count as sharp.
    bool sharp_edges_as_curves = false;
    //! A moving node is never carried to a vertex next to another node (the other node's vertex
    //! or its 1-ring, next_to_other_nodes; a node already there may stay), in descent steps,
    //! curve slides and hop sweeps. Two nodes on one triangle leave the patches or the arc
    //! between them narrower than a triangle, where the orientation constraints become
    //! infeasible; this matters for dense layouts with a few edges per patch side. Off by
    //! default (it can also end higher or folded); `quadsketch-cli optimize` runs again with it
    //! when a run keeps fold-overs or falls back to an earlier state (core/nodeopt/retry.h).
    bool keep_nodes_apart = false;
    //! Nodes that already sit next to another node (on its 1-ring, as a displaced sketch puts
    //! them) are first moved apart (core/layout/node_shift.h separate_nodes); the optimization
    //! then starts from that layout (E_init, the initial fallback). keep_nodes_apart only keeps
    //! nodes from getting there. Off by default (`optimize --separate-nodes`).
    bool separate_crowded_nodes = false;
    //! Keep the layout mirror symmetric (core/nodeopt/symmetric_step.h): every descent step's
    //! targets are symmetrized (a pair moves as mirror images about the plane, a node that is
    //! its own mirror moves in the plane; a held node's mirror follows it), a trial in which a
    //! pair could not be realized as mirror images is built again with that pair held, and what
    //! moves single nodes is off (symmetric_node_options: hop polish, sliding along curves,
    //! separation of crowded nodes). Its node_mirror has one entry per layout node. Null: off.
    std::shared_ptr<const NodeSymmetry> symmetry;
  } moves;

  //! The hop polish (docs/design.md, "Hop polish").
  struct Polish {
    //! Polish by discrete hops (discrete.h hop_sweep) when a descent phase ends: the descent can
    //! stop in a local optimum of E for the node carried by its current (relocated) vertex,
    //! which a hop to a neighbouring vertex leaves. A sweep tries, each kept only when it lowers
    //! E: every relocation undone at once, sharp cone vertices, then the relocated nodes
    //! (farthest off their vertex first) hop to neighbours (at their original positions) in the
    //! direction of the relocation. When E fell, the state is kept (a step with phase "hop")
    //! and the descent resumes. One sweep of the collective and cone passes also runs before
    //! the descent when some node has a cone candidate (not counted in the sweeps' limit), so
    //! that nodes displaced from sharp corners return before the descent drags their neighbours
    //! along; without sharp cone vertices the first descent phase is the same with or without
    //! the polish. Collective optima (all nodes shifted together, e.g. a rotated cube layout on
    //! a sphere) are not left this way. Callers that drive the descent one step per call
    //! (max_steps = 1) turn it off: a sweep extends the call by tuning.hop_descent_steps.
    bool enabled = true;
  } polish;

  //! The fold-over removal at the end (docs/design.md, "Fold-over removal").
  struct Folds {
    //! A last solve with strict orientation constraints (docs/design.md, "Orientation
    //! constraints"; core/param/orientation.h) when fold-overs remain after the descent, with
    //! the PipelineOptions' orientation options (CLI: --no-orientation clears it).
    bool orientation = true;
    bool stiffen = true;  //!< stiffening when fold-overs remain after that
  } folds;

  //! How the run uses the machine and when it ends; the results do not depend on these except
  //! `stop` (and reuse_field up to solver round-off).
  struct Run {
    //! Threads the node optimization may use, on machines that report as many hardware threads
    //! (at least 2). ≥ 2: a node's hop candidates are solved two at a time, one on a second
    //! thread (hop_sweep's jobs; each candidate's continued Pipeline copies its field
    //! factorizations first), and when fold-overs remain after a polish that kept hops, the
    //! state before the polish (the first fallback of the fold-over removal) is solved and
    //! oriented on a second thread while the final state is oriented; its result and reports
    //! are used exactly when the sequential order would have tried it, otherwise it is stopped
    //! at its next poll and discarded. ≥ 3 (with reuse_field): also a trial with switches is
    //! solved on a second thread while this one solves its retry without switches, which is
    //! ready when the re-layout is rejected (more CPU: on two cores the two solves slow each
    //! other down). The same results for every value.
    int threads = 2;
    //! A trial in which nodes change their vertex (re-routed arcs), and a hop evaluation,
    //! continues the current Pipeline (Pipeline(mesh, layout, previous)): a copy of its field
    //! solver re-solved for the new layout by CrossFieldSolver::update_layout, which collects
    //! the constraints of the trial's (relocated) geometry again (curvature updated around moved
    //! vertices) and keeps the factorizations' analyses, so the field is a fresh Pipeline's up
    //! to solver round-off. false: a fresh Pipeline per such trial (curvature, constraints,
    //! every analysis and factorization redone). `optimize --integer` turns it off (nodes on
    //! shared iso-lines).
    bool reuse_field = true;
    //! Ends the node movement early when it returns true (a time limit): polled before each
    //! descent step and hop sweep and before each candidate solve inside a sweep. The state
    //! reached so far is kept (a sweep keeps the hops it made), finish() still removes
    //! fold-overs, and NodeOptResult::stopped says so. Empty: no early end.
    std::function<bool()> stop;
  } run;

  //! For tests and benchmarks only (see NodeOptTuning).
  NodeOptTuning tuning;
};

struct NodeOptResult {
  TriMesh mesh;   //!< the mesh with the final vertex relocations (same connectivity)
  Layout layout;  //!< the layout with the final node vertices and re-routed arcs
  //! Per-face weights of the final solve (empty: all 1; set when stiffening ran).
  std::vector<double> face_weights;
  double E_init = 0;     //!< residual before any step (unweighted, length²)
  double E_descent = 0;  //!< residual after the descent, before stiffening
  double E_final = 0;    //!< residual of the final solve (after stiffening, if it ran)
  int foldovers_init = 0, foldovers_descent = 0, foldovers_final = 0;
  int steps = 0, accepted = 0, halvings = 0;  //!< descent steps (hop sweeps not included)
  //! Nodes that slid along a curve (NodeOptOptions::Moves::slide_on_curves) at the start.
  int sliding_nodes = 0;
  //! NodeOptOptions::Moves::separate_crowded_nodes: the nodes next to another node in the input,
  //! and the ids of those moved apart before the initial solve (0 and empty when off).
  int crowded_nodes = 0;
  std::vector<int> separated_nodes;
  //! Hop sweeps run (NodeOptOptions::polish; with the one before the descent).
  int hop_rounds = 0;
  //! Node moves kept by those sweeps (hops to other vertices and undone relocations).
  int hops = 0;
  //! Fold-overs remained after the fold-over removal at the polished state but fewer (or as
  //! many at a lower E_final) at the state before the first hop: that state was returned
  //! (E_descent is then its E, above the last accepted step's).
  bool polish_reverted = false;
  //! Fold-overs remained after the fold-over removal at the end of the descent but fewer (or as
  //! many at a lower E_final) at the accepted state with the fewest fold-overs before the
  //! removal: that state was returned.
  bool fewest_foldovers_reverted = false;
  //! The fold-over removal fell back to the initial state (by the fewest-fold-over fallback, the
  //! one before the polish, or NodeOptTuning::initial_fallback): the node movement was given
  //! up.
  bool initial_reverted = false;
  //! The returned state's fold-overs were removed by the untangling (OrientationOptions::
  //! untangle), the last resort after the orientation constraints at every state tried and
  //! stiffening left some.
  bool untangled = false;
  //! The state returned is the fold-free state with the lowest E that the descent accepted (the
  //! initial state included): the fold-over removal of the later states ended higher, folded, or
  //! not structurally equivalent. The rule: the lowest E among the fold-free, structurally
  //! equivalent states, never worse than a fold-free input.
  bool fold_free_reverted = false;
  int stiffening_iterations = 0;
  //! NodeOptOptions::Run::stop (or DiscreteOptions::stop) ended the node movement before the
  //! descent and polish (the discrete sweeps) were over.
  bool stopped = false;
  //! The final solve uses the orientation constraints: re-solving the final (mesh, layout)
  //! needs ParamOptions::orientation.enabled (and `orientation_options`) to reproduce it;
  //! `pipeline` then holds that constrained solve. foldovers_descent is the count before.
  bool orientation_constraints = false;
  OrientationOptions orientation_options;  //!< the options of that solve (enabled = true)
  OrientationReport orientation;           //!< of the constrained solve (ran = false: none)
  std::vector<StepReport> reports;         //!< one per step (descent, then stiffening)
  double time_s = 0;
  //! The pipeline solved (field + parameterization, no stiffening weights) at the final
  //! (mesh, layout) of the descent, for callers that display or extract it without solving
  //! again. Its mesh is `mesh` and its layout is `layout`.
  std::shared_ptr<Pipeline> pipeline;
  //! The descent's own Pipeline at the final (mesh, layout), solved with exactly the given
  //! PipelineOptions (the same object as `pipeline` unless the final orientation-constrained
  //! solve replaced that): a valid `start` for a further optimize_nodes call.
  std::shared_ptr<Pipeline> descent_pipeline;
};

//! Counters of the work done by optimize_nodes (for benchmarks and the reuse test).
struct NodeOptStats {
  int fresh_pipelines = 0;  //!< Pipelines built from scratch (the start, run.reuse_field off)
  int relayouts = 0;        //!< Pipelines continued from the current one (a node switched)
  //! Re-layouts solved on this thread whose parameterization solver was set up beside the
  //! field and kept (Pipeline::param_solver_prepared)
  int prepared_param_solvers = 0;
  int reused_solves = 0;       //!< re-solves of the previous Pipeline after vertices moved
  int gradient_reuses = 0;     //!< steps after a rejection that reused the gradient
  int tabu_steps = 0;          //!< trials rejected as repeated switches (tuning.switch_tabu)
  int parallel_retries = 0;    //!< re-layouts solved beside their retry (run.threads ≥ 3)
  int parallel_hop_jobs = 0;   //!< hop candidates prepared for a two-at-a-time solve
  int reused_hop_solves = 0;   //!< sweeps whose kept state was its best candidate's solve
  int parallel_fallbacks = 0;  //!< speculative fallback solves that were used (run.threads ≥ 2)
  bool warm_start = false;     //!< the given start Pipeline served as the initial solve
};

//! Nodes that the optimizer may move: not pinned, not an end of a pinned arc, not on the mesh
//! boundary or a feature edge (v1: such nodes stay). Indices into layout.nodes.
std::vector<int> movable_nodes(const TriMesh& mesh, const Layout& layout);

//! The separation of NodeOptOptions::Moves::separate_crowded_nodes: separate_nodes for the nodes
//! that movable_nodes allows to move; nullopt when the layout is invalid (nothing is moved then).
std::optional<SeparateNodesResult> separate_movable_nodes(const TriMesh& mesh,
                                                          const Layout& layout);

//! The node optimization one unit at a time, for callers that show every state (the editor):
//! the same units, in the same order, with the same results as optimize_nodes, which runs
//! `while (step()) {}` and then finish(). A unit is a descent step or a hop sweep
//! (NodeOptOptions::polish); each is reported to the observer given to that call.
//! Not thread-safe: one thread drives it (it may start its own second threads).
class NodeOptimizer {
 public:
  //! The initial solve (or \p start, as for optimize_nodes), reported to \p observer. The
  //! input mesh's positions are the "original" positions for the whole optimization.
  //! \throw as optimize_nodes.
  NodeOptimizer(const TriMesh& mesh, const Layout& layout, const PipelineOptions& options,
                const NodeOptOptions& node_options = {}, Observer* observer = nullptr,
                std::shared_ptr<Pipeline> start = nullptr);
  ~NodeOptimizer();
  NodeOptimizer(const NodeOptimizer&) = delete;
  NodeOptimizer& operator=(const NodeOptimizer&) = delete;

  //! Runs the next unit. False when the descent and the polish are over (a last hop sweep that
  //! kept nothing may have run in this call): call finish(). \throw Cancelled, SolverError (the
  //! exact gradient's solves), and the errors of a trial that optimize_nodes passes on.
  bool step(Observer* observer = nullptr);
  //! Pins for the next steps: \p pinned has one flag per layout node, \p arc_pinned one per
  //! layout arc (by index into layout().nodes / layout().arcs; empty: the arcs' flags stay).
  //! A pinned node does not move from now on, a released one may. A pinned arc holds its end
  //! nodes (as pinned nodes) and its route (no end moves, so it is never re-routed). An earlier
  //! state kept for the fold-over removal in which a newly pinned node, or a newly pinned arc's
  //! route or end nodes, stands elsewhere is dropped.
  //! \throw std::invalid_argument on a wrong number of flags, std::logic_error after finish().
  void set_pinned(const std::vector<char>& pinned, const std::vector<char>& arc_pinned = {});

  //! The current (last accepted) state.
  const TriMesh& mesh() const;
  const Layout& layout() const;
  //! Every report so far (the initial solve first).
  const std::vector<StepReport>& reports() const;
  //! The Pipeline solved at the current state (solved again when the last trial, rejected,
  //! re-solved it in place). Valid until the next step(); do not solve it yourself.
  std::shared_ptr<Pipeline> pipeline(Observer* observer = nullptr);
  //! Fold-over removal at the current state (and the fallbacks) and the result; ends the
  //! optimization (no step() or pipeline() after it).
  NodeOptResult finish(Observer* observer = nullptr, NodeOptStats* stats = nullptr);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

//! Runs the node optimization. The input mesh's positions are the "original" positions (each
//! relocated vertex lies on the original surface; a vertex given up by a node gets its original
//! position back). Every step is reported to \p observer, which is polled between solves.
//! Steps in which no node changes its vertex re-solve the previous Pipeline in place (geometry
//! updated, solver setup and factorization patterns kept); a step that re-routes arcs builds a
//! new one (without re-validating: re-routing keeps the layout's structure), continued from the
//! current one (NodeOptOptions::Run::reuse_field).
//! The parameterizations of the trials take their fill-reducing ordering from one nested
//! dissection of the mesh's vertex graph (ParamOptions::vertex_order) instead of an AMD ordering
//! of every new reduced matrix: on meshes where the initial Pipeline computes it beside the field
//! (PipelineOptions::order_vertices) the initial solve uses it too; on smaller ones it is computed
//! beside the initial solve, which keeps AMD. Given PipelineOptions that already carry a vertex
//! order keep it.
//! A trial state (descent step, hop candidate, fold-over removal attempt) whose solve throws
//! InfeasibleLayoutError (its constraints contradict each other) or SolverError is rejected (as
//! a step that raises E; a fold-over removal attempt keeps the error's message in
//! NodeOptResult::orientation); every other error propagates.
//! \p start, when given, is a Pipeline already solved (compute_parameterization) at exactly
//! (\p mesh, \p layout) with \p options: it serves as the initial solve. \p stats, when given,
//! receives work counters.
//! \throw InvalidInputError (invalid layout, invalid options), InfeasibleLayoutError (the
//! initial state), SolverError (the initial state), Cancelled.
NodeOptResult optimize_nodes(const TriMesh& mesh, const Layout& layout,
                             const PipelineOptions& options,
                             const NodeOptOptions& node_options = {}, Observer* observer = nullptr,
                             std::shared_ptr<Pipeline> start = nullptr,
                             NodeOptStats* stats = nullptr);

}  // namespace qs
