// Discrete singularity relocation (BZK09, paper §6.3): nodes hop to neighbouring vertices
// (re-routing their arcs) when that lowers the residual E. The baseline runs it alone (slow on
// purpose: every candidate is a full field + parameterization solve); the continuous optimizer
// uses one sweep as its polish when the descent has converged (NodeOptOptions::hop_polish).
#pragma once

#include <functional>
#include <vector>

#include "core/base/progress.h"
#include "core/layout/layout.h"
#include "core/mesh/mesh.h"
#include "core/nodeopt/optimizer.h"
#include "core/pipeline/pipeline.h"

namespace qs {

struct DiscreteOptions {
  int max_steps = 25;            //!< sweeps over all nodes
  int max_evaluations = 2000;    //!< total candidate solves (work cap)
  RelocationOptions relocation;  //!< re-routing of the moved node's arcs
};

//! Runs the discrete baseline on the original mesh positions (no vertex relocation). Nodes move
//! one at a time (Gauss–Seidel): a node's best neighbour is accepted at once when it lowers E.
//! Stops when a sweep improves nothing, or at max_steps / max_evaluations. One StepReport per
//! sweep. \throw InvalidInputError, TopologyError, SolverError, Cancelled.
NodeOptResult relocate_nodes_discrete(const TriMesh& mesh, const Layout& layout,
                                      const PipelineOptions& options,
                                      const DiscreteOptions& discrete = {},
                                      Observer* observer = nullptr);

//! Solves a state (mesh positions + layout) and returns its residual E (unweighted, length²)
//! and fold-over count; false when the solve fails (the state is then not taken).
using HopEvaluator =
    std::function<bool(const TriMesh& mesh, const Layout& layout, double& E, int& foldovers)>;

struct HopSweepOptions {
  //! Per node, at most this many neighbouring vertices are tried (≤ 0: all free neighbours).
  //! With a preferred direction the ones best aligned with it come first.
  int max_candidates = 0;
  //! With a preferred direction, only neighbours w with cos∠(x_w − x_v, direction) at least
  //! this are tried (x: positions in the original mesh).
  double min_direction_cos = -1;
  int max_evaluations = 2000;    //!< candidate solves in this sweep (work cap)
  RelocationOptions relocation;  //!< re-routing of the moved node's arcs, orientation check
};

struct HopSweepResult {
  int moved = 0;        //!< nodes that hopped
  int evaluations = 0;  //!< candidate solves
  double E = 0;         //!< residual of the final state
  int foldovers = 0;    //!< fold-overs of the final state
};

//! One Gauss–Seidel sweep of discrete hops. Each node of \p nodes (indices into layout.nodes), in
//! order, tries its free neighbouring vertices w (not forbidden_relocation_vertices): the node
//! moves to w (its arcs re-routed by move_node_and_reroute, routing metric \p mesh), its old
//! vertex gets back its position in \p original, w keeps its position in \p mesh; a candidate
//! whose 1-rings would leave RelocationOptions' orientation bounds is skipped. The candidate
//! with the lowest E is kept at once when it is below the current E (\p E at the start).
//! \p directions is empty (no preference) or has one preferred direction per entry of \p nodes
//! (3D; a zero vector: the node is skipped). \p mesh and \p layout are updated in place.
//! \pre mesh and original have the same connectivity; layout is valid on them.
//! \throw Cancelled (polled before every solve).
HopSweepResult hop_sweep(const TriMesh& original, TriMesh& mesh, Layout& layout,
                         const std::vector<int>& nodes, const std::vector<Vec3>& directions,
                         double E, int foldovers, const HopSweepOptions& options,
                         const HopEvaluator& evaluate, Observer* observer = nullptr,
                         const RerouteContext* context = nullptr);

}  // namespace qs
