// Discrete singularity relocation (BZK09, paper §6.3): nodes hop to neighbouring vertices
// (re-routing their arcs) when that lowers the residual E. The baseline runs it alone (slow on
// purpose: every candidate is a full field + parameterization solve); the continuous optimizer
// uses one sweep as its polish when the descent has converged (NodeOptOptions::polish).
#pragma once

#include <functional>
#include <vector>

#include "core/base/progress.h"
#include "core/layout/layout.h"
#include "core/mesh/geometry.h"
#include "core/mesh/mesh.h"
#include "core/nodeopt/optimizer.h"
#include "core/pipeline/pipeline.h"

namespace qs {

struct DiscreteOptions {
  int max_steps = 25;            //!< sweeps over all nodes
  int max_evaluations = 2000;    //!< total candidate solves (work cap)
  RelocationOptions relocation;  //!< re-routing of the moved node's arcs
  //! A node's candidates are solved two at a time (hop_sweep's jobs) when the machine
  //! reports two hardware threads; same result as one at a time.
  bool parallel = true;
  //! Ends the run early when it returns true (checked before each candidate solve), keeping the
  //! moves made so far: a time cap, as in the paper's comparison (§6.3: "after max 1h"). The
  //! sweep it ends is reported like any other. Empty: no early end.
  std::function<bool()> stop;
  //! Called after each node move the run keeps, with the new E (length²): the trajectory within
  //! a sweep, whose report comes only at its end. Empty: not called.
  std::function<void(double E)> on_move;
};

//! Runs the discrete baseline on the original mesh positions (no vertex relocation). Nodes move
//! one at a time (Gauss–Seidel): a node's best neighbour is accepted at once when it lowers E.
//! Stops when a sweep improves nothing, at max_steps / max_evaluations, or when
//! DiscreteOptions::stop says so. One StepReport per sweep. A candidate whose solve throws
//! InfeasibleLayoutError or SolverError is not taken; other errors propagate.
//! \throw InvalidInputError, InfeasibleLayoutError and SolverError (the initial solve), Cancelled.
NodeOptResult relocate_nodes_discrete(const TriMesh& mesh, const Layout& layout,
                                      const PipelineOptions& options,
                                      const DiscreteOptions& discrete = {},
                                      Observer* observer = nullptr);

//! Solves a state (mesh positions + layout) and returns its residual E (unweighted, length²)
//! and fold-over count; false when the solve fails (the state is then not taken).
using HopEvaluator =
    std::function<bool(const TriMesh& mesh, const Layout& layout, double& E, int& foldovers)>;

//! One candidate's solve, prepared on the sweep's thread and run on any thread: it shares no
//! mutable state with the caller or with other jobs (its Pipeline owns its factorizations).
//! Returns false for a failed solve (E and foldovers then unset).
using HopJob = std::function<bool(double& E, int& foldovers)>;
//! Prepares the job of one candidate (mesh, layout); called on the sweep's thread only.
using HopJobMaker = std::function<HopJob(const TriMesh& mesh, const Layout& layout)>;

struct HopSweepOptions {
  //! Per node, at most this many neighbouring vertices are tried (≤ 0: all free neighbours).
  //! With a preferred direction the ones best aligned with it come first.
  int max_candidates = 0;
  //! With a preferred direction, only neighbours w with cos∠(x_w − x_v, direction) at least
  //! this are tried (x: positions in the original mesh).
  double min_direction_cos = -1;
  int max_evaluations = 2000;    //!< candidate solves in this sweep (work cap)
  RelocationOptions relocation;  //!< re-routing of the moved node's arcs, orientation check
  //! No hop onto a vertex next to another node (next_to_other_nodes).
  bool keep_nodes_apart = false;
  //! Before its neighbours, a node whose vertex is relocated (its position in the mesh differs
  //! from \p original) tries staying on that vertex with the relocation undone (the vertex back
  //! at its original position, layout unchanged): the continuous descent cannot reach a vertex's
  //! own original position exactly, which matters at sharp (cone) vertices.
  bool try_restore = false;
  bool try_neighbours = true;  //!< false: only the restore candidate (try_restore)
  //! When not empty (one list per entry of the sweep's nodes): node i tries exactly the vertices
  //! targets[i], in order (any vertices, not only neighbours; forbidden ones are skipped),
  //! instead of its neighbours.
  std::vector<std::vector<int>> targets;
  //! With targets: a target that is a curve neighbour of the node's vertex on these curves is a
  //! step along the curve (its vertex may lie on the curve; the node's arcs along the curve move
  //! with it, move_node_and_reroute's CurveWalk).
  const CurveNetwork* curves = nullptr;
  //! The sweep stops after this many candidate solves in a row that found no lower E
  //! (≤ 0: no limit); with the most promising nodes first, the rest rarely pays.
  int max_failures = 0;
  //! Ends the sweep when it returns true (checked before each candidate solve); the best
  //! candidate of the node in progress among those solved is still taken. Empty: never.
  std::function<bool()> stop;
  //! Called after each node move the sweep keeps, with the new E. Empty: not called.
  std::function<void(double E)> on_move;
};

struct HopSweepResult {
  int moved = 0;         //!< nodes that hopped
  int evaluations = 0;   //!< candidate solves
  bool stopped = false;  //!< HopSweepOptions::stop ended the sweep
  double E = 0;          //!< residual of the final state
  int foldovers = 0;     //!< fold-overs of the final state
};

//! Angle deficit 2π − Σ angles at every vertex (GeometryCache::angle_defect; radians), 0 at
//! boundary vertices.
std::vector<double> vertex_angle_deficits(const GeometryCache& geometry);

//! Hop candidates at sharp cone vertices, which the continuous descent cannot reach (it never
//! places a node exactly on a vertex's original position, and a relocated cone vertex loses its
//! cone). A node of valence k has index ι = (4 − k)/4 and fits a vertex whose angle deficit is
//! near 2πι (a polycube corner: 3 patches at π/2 deficit; 5 at −π/2).
struct ConeCandidates {
  //! Nodes on a fitting vertex whose relocation is not undone (restore candidates).
  std::vector<int> snap_nodes;
  //! Nodes on a vertex that does not fit, with fitting free vertices within the search rings
  //! (nearest ring first): hop candidates.
  std::vector<int> hop_nodes;
  std::vector<std::vector<int>> hop_targets;
};

//! A vertex fits a node of index ι ≠ 0 when |deficit − 2πι| ≤ tolerance · π/2 (nodes of index
//! 0 have no candidates, so smooth meshes have none). Searches \p rings rings of the original
//! mesh around each of \p nodes (indices into layout.nodes) and keeps at most \p max_targets
//! per node. \p valence: per node of the layout (LayoutTopology::valence); \p deficits:
//! vertex_angle_deficits(original).
ConeCandidates cone_candidates(const TriMesh& original, const TriMesh& mesh, const Layout& layout,
                               const std::vector<int>& nodes, const std::vector<int>& valence,
                               const std::vector<double>& deficits, double tolerance, int rings,
                               int max_targets);

//! One Gauss–Seidel sweep of discrete hops. Each node of \p nodes (indices into layout.nodes), in
//! order, tries its free neighbouring vertices w (not forbidden_relocation_vertices): the node
//! moves to w (its arcs re-routed by move_node_and_reroute, routing metric \p mesh), its old
//! vertex gets back its position in \p original, w keeps its position in \p mesh; a candidate
//! whose 1-rings would leave RelocationOptions' orientation bounds is skipped. The candidate
//! with the lowest E is kept at once when it is below the current E (\p E at the start).
//! \p directions is empty (no preference) or has one preferred direction per entry of \p nodes
//! (3D; a zero vector: no preference for that node). \p mesh and \p layout are updated in
//! place. \p evaluate solves one candidate on this thread. With \p jobs (not null), a node's
//! candidates are solved two at a time, one on a second thread (the last odd one by
//! \p evaluate); the candidates and the kept move are those of the one-at-a-time order: the
//! results are read in that order, and a solve past the point where the sequential sweep would
//! have stopped (max_failures) is discarded, not counted.
//! \pre mesh and original have the same connectivity; layout is valid on them.
//! \throw Cancelled (polled before every solve or pair of solves).
HopSweepResult hop_sweep(const TriMesh& original, TriMesh& mesh, Layout& layout,
                         const std::vector<int>& nodes, const std::vector<Vec3>& directions,
                         double E, int foldovers, const HopSweepOptions& options,
                         const HopEvaluator& evaluate, Observer* observer = nullptr,
                         const RerouteContext* context = nullptr,
                         const HopJobMaker* jobs = nullptr);

}  // namespace qs
