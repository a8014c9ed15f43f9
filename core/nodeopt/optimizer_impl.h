// Private to core/nodeopt (included by the files below only; not part of the API): the state of
// a NodeOptimizer between its units (NodeOptimizer::Impl) and its phases, each defined in its
// own file (docs/design.md, "Node optimization"):
// - optimizer.cpp: construction (the initial solve), the evaluation of states, the API glue;
// - mobility.cpp: which nodes move and how (pins, the curves nodes slide on, nodes kept apart;
//   "Node relocation");
// - descent.cpp: the descent step ("Gradient", "Step length", "Straightest geodesics",
//   "Retries");
// - hop_polish.cpp: the hop sweeps ("Hop polish");
// - foldover_removal.cpp: finish(), the fold-over removal and the result rule ("Fold-over
//   removal", "Result rule").
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <memory>
#include <utility>
#include <vector>

#include "core/base/progress.h"
#include "core/layout/layout.h"
#include "core/mesh/geometry.h"
#include "core/mesh/mesh.h"
#include "core/mesh/surface_point.h"
#include "core/nodeopt/optimizer.h"
#include "core/nodeopt/relocation.h"
#include "core/nodeopt/symmetric_step.h"
#include "core/pipeline/pipeline.h"

namespace qs {

// The helpers the phase files share (names are private to core/nodeopt).
namespace nodeopt_detail {

// Fixed settings of the node optimization (docs/design.md, "Step length", "Retries",
// "Hop polish").
// A descent phase ends after more than this many halvings of α.
constexpr int kMaxHalvings = 5;
// Step length l = α · scale · ‖d‖: ⅔ for the estimator, 1 for the exact gradient (paper §7.2).
constexpr double kEstimatorScale = 2.0 / 3.0;
constexpr double kExactScale = 1.0;
// Nodes whose step is shorter than this fraction of the mean edge length do not move; when no
// node moves the descent has converged.
constexpr double kMinStepRelative = 1e-4;
// A sliding node stays where its curve turns by more than this (degrees).
constexpr double kCurveCornerDeg = 30.0;
// The switch tabu (NodeOptTuning::switch_tabu) rejects a trial when at least this fraction of
// its switches repeat those of the last trial rejected at the current α.
constexpr double kSwitchTabuOverlap = 0.5;
// A vertex fits a cone of index k when |deficit − 2π·k| ≤ this · π/2 (discrete.h
// cone_candidates).
constexpr double kHopConeTolerance = 0.25;
// Candidate solves per sweep for each of the two cone passes.
constexpr int kHopConeMaxEvaluations = 64;
// A trial whose solve throws InfeasibleLayoutError or SolverError is rejected (optimizer.h,
// optimize_nodes); other errors propagate.

// One solve of field + parameterization. The Pipeline is shared: a later trial without node
// switches re-solves it in place (then it no longer holds this evaluation's solution).
struct Evaluation {
  std::shared_ptr<Pipeline> pipeline;
  double E = 0;
  int foldovers = 0;
};

// Solves the field and the parameterization of ev.pipeline and measures E (unweighted) and
// the fold-overs into \p ev.
void solve_and_measure(Evaluation& ev, const PipelineOptions& options);

// A new Pipeline for (\p mesh, \p layout) (\p validate: the layout is validated first), solved
// and measured.
Evaluation evaluate_fresh(const TriMesh& mesh, const Layout& layout, const PipelineOptions& options,
                          bool validate);

// True when \p p was built for exactly this mesh (positions) and layout (what the solves use).
bool pipeline_matches(const Pipeline& p, const TriMesh& mesh, const Layout& layout);

// A node's position on its curve (NodeOptOptions::Moves::slide_on_curves): on the segment from its
// vertex's original point towards curve neighbour `toward` at fraction t ∈ [0, 1) (toward −1:
// on the vertex).
struct CurvePoint {
  int toward = -1;
  double t = 0;
};

struct State {
  TriMesh mesh;
  Layout layout;
  std::vector<SurfacePoint> anchor;  // per node, on the original mesh
  std::vector<CurvePoint> curve;     // per node (sliding nodes only)
};

// Completes \p r with the node positions of (mesh, layout), appends it to \p reports and
// streams it to the observer.
void emit_step(StepReport r, const TriMesh& mesh, const Layout& layout,
               std::vector<StepReport>& reports, Observer* observer);

// The curves nodes slide on (NodeOptOptions::Moves::slide_on_curves): the layout's feature
// edges, the boundary and, with sharp_edges_as_curves, the sharp edges of \p mesh at the field's
// sharp angle. Empty when off.
CurveNetwork curve_network(const TriMesh& mesh, const GeometryCache& g, const Layout& layout,
                           const PipelineOptions& options, const NodeOptOptions& no);

}  // namespace nodeopt_detail

// The optimization's state between units (NodeOptimizer::step), and the units themselves.
struct NodeOptimizer::Impl {
  using CurvePoint = nodeopt_detail::CurvePoint;
  using Evaluation = nodeopt_detail::Evaluation;
  using State = nodeopt_detail::State;

  // The caller's; after the initial solve, plus the vertex order that every later Pipeline
  // uses (the initial Pipeline's, or computed here).
  PipelineOptions options;
  const NodeOptOptions no;
  const RelocationOptions relocation;  // the defaults (relocation.h)
  const std::chrono::steady_clock::time_point t_start = std::chrono::steady_clock::now();
  const TriMesh original;        // the input positions (each relocated vertex lies on this surface)
  Observer* observer = nullptr;  // the caller's, for the current step() or finish()
  NodeOptResult result;
  NodeOptStats counters;
  State state;
  std::vector<int> movable;
  const GeometryCache original_geometry;
  const double mean_edge;
  // Feature and boundary curves (moves.slide_on_curves; empty when off).
  const CurveNetwork curves;
  Evaluation current;
  // False when current.pipeline was re-solved for a rejected trial (it then holds the trial's
  // positions, not state's).
  bool current_solved = true;
  // Re-routing keeps the patch count: computed once.
  const RerouteContext reroute;
  // Symmetric optimization (NodeOptOptions::Moves::symmetry; null when off).
  const std::unique_ptr<const SymmetricStepper> symmetric;
  double alpha;
  // Gradients and node-Voronoi cells depend on the state only: kept across rejected steps.
  std::vector<Vec3> grad;
  double scale = 1;
  std::vector<int> cell;
  bool state_changed = true;
  // Descent phases: the first has descent.max_steps steps; a hop sweep that moves nodes starts a
  // new one (α reset) with at least tuning.hop_descent_steps more.
  int step_budget;
  std::unique_ptr<State> pre_polish;  // the state before the first kept hop
  // The accepted state with the fewest fold-overs (equal: the later, lower E), kept while the
  // current state has more: the second fallback of the fold-over removal.
  std::unique_ptr<State> fewest_folds;
  int fewest_folds_count = 0;
  // The start (NodeOptTuning::initial_fallback): the last fallback of the fold-over removal.
  std::unique_ptr<State> initial_state;
  // The candidates of the result rule in finish(), by E: the initial state when it is
  // fold-free (always kept), and the kFoldFreeKept fold-free accepted states with the lowest E.
  static constexpr size_t kFoldFreeKept = 4;
  std::vector<std::pair<double, std::shared_ptr<const State>>> fold_free;
  std::pair<double, std::shared_ptr<const State>> fold_free_initial;
  int phase_halvings = 0;
  int stalled_steps = 0;      // accepted steps in a row with a gain below tuning.stall_gain
  double accepted_alpha = 0;  // α of the phase's last accepted descent step (0: none yet)
  // Per movable node: the vertex it switched to in the last trial rejected at the current α, or
  // -1 (tuning.switch_tabu); and the targets of the trial being built.
  std::vector<int> rejected_target, target;
  // Per movable node: its step length factor (halved for a sliding node whose switch raised E).
  std::vector<double> damping;
  std::vector<double> deficits;  // angle deficits of the original mesh (cone passes), on demand
  int polish_rounds = 0;         // sweeps after a descent phase (tuning.max_hop_rounds)
  bool started = false;          // the cone sweep before the descent is done
  bool descent_over = false;     // no further unit: finish() remains
  bool finished = false;
  // Per vertex: the nodes of the trial layout whose vertex or 1-ring (original connectivity)
  // it is (keep_nodes_apart); empty when off.
  std::vector<int> near_count;

  // ---- optimizer.cpp ----
  // The initial solve (\p start when it matches; see optimize_nodes) and its report.
  Impl(const TriMesh& mesh, const Layout& layout, const PipelineOptions& options_in,
       const NodeOptOptions& no_in, Observer* obs, std::shared_ptr<Pipeline> start);

  // The Pipeline of a state whose nodes moved to other vertices (re-routed layout): continued
  // from the current one (run.reuse_field: it reuses the field solver, so update_layout needs no
  // analysis and numeric factorizations only for a changed constraint set or a drop pass, and
  // the geometry; see Pipeline(mesh, layout, previous)), or fresh. \p own_solvers: the
  // continued Pipeline copies the field factorizations it shares with the current one, so that
  // it can be solved on another thread (run.threads).
  std::shared_ptr<Pipeline> switched_pipeline(const TriMesh& m, const Layout& l, bool own_solvers);
  // A state whose nodes moved to other vertices, solved (switched_pipeline) and measured.
  Evaluation evaluate_switched(const TriMesh& m, const Layout& l);

  bool stop_requested() const { return no.run.stop && no.run.stop(); }
  // A second thread may solve beside this one: run.threads ≥ \p threads and the machine reports
  // two hardware threads.
  bool parallel(int threads) const;

  // ---- mobility.cpp ----
  // A node on this vertex is on a curve: it slides along it while the curve goes on straight
  // there (curves.slides), and stays on a curve end, junction or corner.
  bool on_curve(int vertex) const { return !curves.empty() && !curves.neighbours[vertex].empty(); }

  // The nodes that may move: those off the curves as movable_nodes says, those on a curve
  // (moves.slide_on_curves) when not pinned and not an end of a pinned arc. Whether a node slides
  // or moves freely depends on the vertex it is on at each step.
  void compute_movable();

  // Slides movable node \p i (node n, on a curve) of \p trial along its curve by the projection
  // of −grad[i] (paper §6.1.1): walks the curve polyline (original positions) from the node's
  // position, stops before a curve end, junction, corner, another node or another arc, and
  // relocates the nearer end of the segment it reaches (the node's vertex, or the next one
  // with the arcs along the curve moved with it). False when the node does not move.
  bool slide_on_curve(State& trial, size_t i, int n, bool no_switch, LayoutObstacles& obstacles,
                      std::vector<char>& switched);
  // Counts the nodes of \p layout into near_count (moves.keep_nodes_apart; cleared when off).
  void count_nodes_near(const Layout& layout);
  // Adds \p d to the count of vertex \p v and of its 1-ring.
  void add_near_count(int v, int d);
  // A node moved from vertex \p from to vertex \p to.
  void move_near_count(int from, int to);
  // Vertex \p u is next to a node other than the one at vertex \p own (moves.keep_nodes_apart).
  bool next_to_other_node(int own, int u) const;
  // Pins changed between steps (NodeOptimizer::set_pinned): per node and, when \p arc_pinned is
  // not empty, per arc (both by index).
  void set_pinned(const std::vector<char>& pinned, const std::vector<char>& arc_pinned);

  // ---- descent.cpp ----
  // One unit of the optimization: the cone sweep before the descent (when it runs), then a descent
  // step, or the hop sweep that ends a descent phase. False when the descent and the polish are
  // over (finish() remains); a last sweep that kept nothing may have run and been reported in that
  // call.
  bool step();
  // The last trial re-solved the current Pipeline in place and was rejected: solve it at the
  // state again.
  void solve_current();

  // ---- hop_polish.cpp ----
  // Hop sweep (discrete.h; NodeOptOptions::polish): all relocations undone at once, cone
  // restores and hops, then relocated nodes try the neighbours in the direction of their
  // relocation. Returns true when E fell (state and current updated). \p cones_only: the sweep
  // before the descent: only the collective and cone passes, and nothing (no
  // solve, no report) when no node has a cone candidate.
  bool hop_round(bool cones_only);
  // When a descent phase ends: a hop sweep; true when nodes hopped and a new phase begins.
  bool polish();

  // ---- foldover_removal.cpp ----
  // The current (just accepted) state, when it has no fold-over and is among the
  // kFoldFreeKept lowest E of the fold-free states so far: a candidate for the result rule.
  void note_fold_free(bool initial = false);
  // Keeps \p before as fewest_folds when the new state (\p after_folds fold-overs) has more
  // fold-overs than the best state so far; drops it when the new state is the best.
  void note_fold_count(const State& before, int after_folds);
  // The end of the optimization at the current state: fold-over removal (orientation
  // constraints, earlier states, stiffening) and the result.
  NodeOptResult finish(NodeOptStats* stats);
};

}  // namespace qs
