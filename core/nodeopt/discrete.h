// Discrete singularity relocation baseline (BZK09, paper §6.3): every step each movable node
// tries its neighbouring vertices (re-routing its arcs) and moves to the one that lowers the
// residual E the most. Slow on purpose: every candidate is a full field + parameterization solve.
#pragma once

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

}  // namespace qs
