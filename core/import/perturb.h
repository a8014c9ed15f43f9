// Random perturbation of a layout's nodes (recovery tests and benchmarks, issue #6): every
// unpinned node moves a given number of edge rings and its arcs are re-routed, keeping the
// layout valid and its structure (same patches, same cyclic orders).
#pragma once

#include <vector>

#include "core/layout/layout.h"
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

struct SeparateNodesOptions {
  //! A node is crowded when another node is fewer than this many mesh edges away (2: on its
  //! vertex's 1-ring, the nodes then share a triangle edge).
  int min_distance = 2;
  int search_rings = 2;   //!< a crowded node moves at most this many edge rings
  int max_attempts = 12;  //!< candidate vertices tried per node (nearest rings first)
  int rounds = 2;         //!< passes over the crowded nodes (a move can free another's way)
};

struct SeparateNodesResult {
  //! The layout with crowded nodes moved (same ids, order; moved nodes lose their output
  //! fields like in PerturbResult).
  Layout layout;
  std::vector<int> crowded_nodes;  //!< ids of the nodes crowded in the input
  std::vector<int> moved_nodes;    //!< ids of the nodes moved
  std::vector<int> still_crowded;  //!< ids of the nodes crowded in the result
};

//! Moves nodes apart that sit closer than options.min_distance edges to another node (node
//! optimization with nodes kept apart, NodeOptOptions::keep_nodes_apart: a displaced layout
//! can put two nodes on one triangle, where the orientation constraints cannot unfold the
//! patches between them). Each crowded node that \p movable allows (one flag per layout node;
//! empty: all) and that perturb_layout could move (not pinned, no pinned or loop arc) goes to
//! the nearest vertex (fewest edge rings, then farthest from the nodes crowding it) where no
//! other node is closer than min_distance, under perturb_layout's rules: in its own patches,
//! on the boundary exactly when it was, its arcs re-routed by shortest paths keeping every
//! cyclic order and patch. A node that no candidate fits stays (still_crowded).
//! \pre \p layout is valid on \p mesh. \throw InvalidInputError for bad options or flags.
SeparateNodesResult separate_nodes(const TriMesh& mesh, const Layout& layout,
                                   const std::vector<char>& movable,
                                   const SeparateNodesOptions& options = {});

}  // namespace qs
