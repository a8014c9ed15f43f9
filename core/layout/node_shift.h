// Shifting layout nodes to nearby mesh vertices with their arcs re-routed, keeping the layout's
// structure (same patches, same cyclic orders): the moves behind separate_nodes (node
// optimization with nodes kept apart) and behind layout perturbation (core/import/perturb.h).
#pragma once

#include <memory>
#include <vector>

#include "core/layout/layout.h"
#include "core/mesh/mesh.h"

namespace qs {

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
  //! fields: point, position, valence).
  Layout layout;
  std::vector<int> crowded_nodes;  //!< ids of the nodes crowded in the input
  std::vector<int> moved_nodes;    //!< ids of the nodes moved
  std::vector<int> still_crowded;  //!< ids of the nodes crowded in the result
};

//! Moves nodes of a layout on a triangle mesh one at a time. Keeps incremental ownership maps
//! (which node or arc holds each vertex and edge, which patch each face is in), so that each
//! move costs time proportional to the patches around the node, not to the whole mesh.
//! Node indices \p n are positions in layout().nodes.
class NodeShifter {
 public:
  //! \pre \p layout is valid on \p mesh (validate_layout); \p mesh outlives the shifter.
  NodeShifter(const TriMesh& mesh, const Layout& layout);
  ~NodeShifter();
  NodeShifter(const NodeShifter&) = delete;
  NodeShifter& operator=(const NodeShifter&) = delete;

  //! The current layout (node vertices and arc paths updated by every kept move).
  const Layout& layout() const;
  //! Indices (into layout().arcs) of the arcs at node n, each once.
  const std::vector<int>& node_arcs(int n) const;
  //! Not pinned, none of its arcs pinned or a loop, at least one arc: the nodes that may move.
  bool may_move(int n) const;

  //! The vertices at exactly \p rings edge rings from node n's vertex (breadth-first distance on
  //! the whole mesh) that can be reached from it within 2·rings + 2 steps without entering
  //! another node or another arc (so they lie in the node's own patches), and that are on the
  //! boundary exactly when the node's vertex is. Ascending vertex index.
  std::vector<int> ring_candidates(int n, int rings);

  //! Moves node n to \p vertex and re-routes its arcs by shortest paths that avoid every other
  //! arc and node, within the node's patches. Keeps the move when the cyclic order of arcs at
  //! the node and at its arcs' other nodes is unchanged and the node's patches are still as
  //! many disks; otherwise restores the previous state and returns false.
  bool try_move(int n, int vertex);

  //! The moves of separate_nodes (same contract; \p options already checked). The shifter is
  //! not to be used afterwards.
  SeparateNodesResult separate(const std::vector<char>& movable,
                               const SeparateNodesOptions& options);

  //! The layout after the moves; moved nodes lose their output fields (point, position,
  //! valence), which described their old vertex. The shifter is not to be used afterwards.
  Layout take_layout();

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

//! Moves nodes apart that sit closer than options.min_distance edges to another node (node
//! optimization with nodes kept apart, NodeOptOptions::Moves::separate_crowded_nodes: a displaced
//! layout can put two nodes on one triangle, where the orientation constraints cannot unfold the
//! patches between them). Each crowded node that \p movable allows (one flag per layout node;
//! empty: all) and that may move (NodeShifter::may_move: not pinned, no pinned or loop arc)
//! goes to the nearest vertex (fewest edge rings, then farthest from the nodes crowding it)
//! where no other node is closer than min_distance, under NodeShifter's rules: in its own
//! patches, on the boundary exactly when it was, its arcs re-routed by shortest paths keeping
//! every cyclic order and patch. A node that no candidate fits stays (still_crowded).
//! \pre \p layout is valid on \p mesh. \throw InvalidInputError for bad options or flags.
SeparateNodesResult separate_nodes(const TriMesh& mesh, const Layout& layout,
                                   const std::vector<char>& movable,
                                   const SeparateNodesOptions& options = {});

}  // namespace qs
