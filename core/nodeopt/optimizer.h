// Node optimization by gradient descent on the residual E of energy (1) (paper §6.1, §7;
// algorithm.md §6): alternating (A) field + parameterization solves with fixed nodes and
// (B) a step of all unpinned nodes along −∇E, traced as straightest geodesics and realized by
// relocating one mesh vertex per node; steps that raise E are undone and α halved.
#pragma once

#include <array>
#include <vector>

#include "core/base/progress.h"
#include "core/layout/layout.h"
#include "core/mesh/mesh.h"
#include "core/nodeopt/gradient.h"
#include "core/nodeopt/relocation.h"
#include "core/nodeopt/stiffening.h"
#include "core/pipeline/pipeline.h"

namespace qs {

enum class GradientMethod { Estimator, Exact };

struct NodeOptOptions {
  int max_steps = 25;    //!< descent steps in total (accepted + rejected)
  int max_halvings = 5;  //!< stop after this many halvings of α
  double alpha = 0.75;   //!< damping factor α of the step length
  //! Step length l = α · scale · ‖d‖: ⅔ for the estimator, 1 for the exact gradient (paper §7.2).
  double estimator_scale = 2.0 / 3.0;
  double exact_scale = 1.0;
  GradientMethod gradient = GradientMethod::Estimator;
  ExactGradientOptions exact;
  bool voronoi_safeguard = true;  //!< limit each trace to the node's Dijkstra-Voronoi cell
  //! Nodes whose step is shorter than this fraction of the mean edge length do not move; when
  //! no node moves the descent has converged.
  double min_step_relative = 1e-4;
  RelocationOptions relocation;
  //! When a step raises E and some nodes changed their vertex in it, retry the step once with
  //! those nodes kept on their vertices before halving α (the switch itself can raise E).
  bool retry_without_switches = true;
  bool stiffen_at_end = true;  //!< stiffening (§7.1) when fold-overs remain after the descent
  StiffeningOptions stiffening;
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
  int steps = 0, accepted = 0, halvings = 0;
  int stiffening_iterations = 0;
  std::vector<StepReport> reports;  //!< one per step (descent, then stiffening)
  double time_s = 0;
};

//! Nodes that the optimizer may move: not pinned, not an end of a pinned arc, not on the mesh
//! boundary or a feature edge (v1: such nodes stay). Indices into layout.nodes.
std::vector<int> movable_nodes(const TriMesh& mesh, const Layout& layout);

//! Runs the node optimization. The input mesh's positions are the "original" positions (each
//! relocated vertex lies on the original surface; a vertex given up by a node gets its original
//! position back). Every step is reported to \p observer, which is polled between solves.
//! \throw InvalidInputError (invalid layout), TopologyError, SolverError, Cancelled.
NodeOptResult optimize_nodes(const TriMesh& mesh, const Layout& layout,
                             const PipelineOptions& options,
                             const NodeOptOptions& node_options = {}, Observer* observer = nullptr);

}  // namespace qs
