// Random perturbation of a layout's nodes (recovery tests and benchmarks, issue #6): every
// unpinned node moves a given number of edge rings and its arcs are re-routed, keeping the
// layout valid and its structure (same patches, same cyclic orders).
#pragma once

#include <vector>

#include "core/layout/layout.h"
#include "core/layout/node_shift.h"
#include "core/mesh/mesh.h"

namespace qs {

struct PerturbLayoutOptions {
  int rings = 1;          //!< graph distance (mesh edges) between a node's old and new vertex
  unsigned seed = 0;      //!< std::mt19937 seed; equal seeds give equal results
  int max_attempts = 12;  //!< candidate vertices tried per node before it is left in place
};

struct PerturbResult {
  //! The perturbed layout (same ids, same order). Moved nodes lose their output fields
  //! (point, position, valence), which described their old vertex.
  Layout layout;
  std::vector<int> moved_nodes;   //!< ids of the nodes that moved
  std::vector<int> stuck_nodes;   //!< ids of unpinned nodes left in place (no valid move)
  std::vector<int> pinned_nodes;  //!< ids of nodes kept because they or one of their arcs
                                  //!< are pinned
};

//! Moves the unpinned nodes one at a time (in layout order). For each node: the vertices at
//! exactly options.rings edge rings (breadth-first distance on the whole mesh) that are not on
//! another node or another arc, lie in the node's own patches (reachable without crossing
//! another arc) and are on the boundary exactly when the node is, are tried in a random order
//! (std::mt19937(seed), deterministic); the node's arcs are re-routed from there by shortest
//! paths that avoid every other arc and node. A move is kept when the cyclic order of arcs at
//! the node and at its neighbours is unchanged and the node's patches are still as many disks;
//! otherwise the next candidate is tried (options.max_attempts at most) and then the node stays
//! (listed in stuck_nodes). Nodes with a pinned arc or a loop arc stay too. The final layout is
//! checked with validate_layout.
//! \pre \p layout is valid on \p mesh (validate_layout); options.rings >= 1.
//! \throw InvalidInputError if the layout is invalid (listing its errors) or rings < 1.
PerturbResult perturb_layout(const TriMesh& mesh, const Layout& layout,
                             const PerturbLayoutOptions& options);

}  // namespace qs
