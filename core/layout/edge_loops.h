// Edge loops of a quad layout: inserting a loop of arcs through a whole poly-chord (a ring of
// 4-sided patches joined by opposite sides), which splits every patch of the chord in two, and
// removing a loop (a chain of arcs that runs straight through valence-4 nodes), which merges
// the patches on its two sides. On the layout's combinatorics (build_topology).
#pragma once

#include <vector>

#include "core/layout/layout.h"
#include "core/mesh/mesh.h"

namespace qs {

//! A poly-chord: 4-sided patches in order, each joined to the next across a pair of opposite
//! sides. Indices into the topology's patches and the layout's arcs.
struct PolyChord {
  std::vector<int> patches;
  //! The arcs the chord crosses, in order: arcs[k] and arcs[k + 1] are opposite sides of
  //! patches[k]. Closed chord: as many arcs as patches (the last patch's far side is arcs[0]);
  //! open chord (both ends on arcs along the mesh boundary): one arc more than patches.
  std::vector<int> arcs;
  bool closed = false;
};

//! The poly-chord that crosses arc \p arc_index. \p topology: build_topology of the valid
//! \p layout. \throw InvalidInputError naming the arc and patch when the arc is dangling, a
//! patch of the chord is not a disk with 4 corners and 4 arc sides (trimmed patches, patches
//! with a hole), the chord passes a patch twice (it crosses itself), or the chord is a single
//! patch joined to itself.
PolyChord find_poly_chord(const Layout& layout, const LayoutTopology& topology, int arc_index);

//! The result of insert_edge_loop; ids are the layout's.
struct EdgeLoopInsertion {
  Layout layout;
  PolyChord chord;              //!< in the input layout's indices
  std::vector<int> new_nodes;   //!< per crossed arc (chord.arcs order): the node splitting it
  std::vector<int> new_arcs;    //!< per chord patch: the arc of the loop across it
  std::vector<int> split_arcs;  //!< per crossed arc: the new id of its second part
};

//! Inserts an edge loop through the poly-chord crossing arc \p arc_id of the valid \p layout on
//! \p mesh:
//! - every crossed arc is split at a new node whose `point` is the arc's midpoint (half its
//!   length along its path; its `vertex` is the path vertex that point snaps to, never an end);
//!   the first part keeps the arc's id, the second gets a new one; both parts lose their `path`
//!   and get `points` (the surface points of their path's vertices between their nodes);
//! - every patch of the chord gets a new arc between the new nodes on its two crossed sides,
//!   given by `points`: the interior vertices of the shortest edge path between the two nodes'
//!   vertices inside the patch (none when there is no such path).
//! The new arcs have no `path`: route_layout routes them on \p mesh, embed_layout embeds them on
//! a working mesh of it. Every patch of the chord is split into two 4-sided patches: the patch
//! count grows by chord.patches.size(). New ids follow the largest existing ones; traced output
//! fields and patches are dropped.
//! \throw InvalidInputError when the layout is not valid (its first error), arc_id is unknown,
//! find_poly_chord refuses the chord, or a crossed arc is a single mesh edge (no vertex for the
//! new node).
EdgeLoopInsertion insert_edge_loop(const TriMesh& mesh, const Layout& layout, int arc_id);

//! An edge loop: arcs in order, each continuing the previous one straight through a valence-4
//! node (the arc opposite it around the node). Indices into the layout.
struct EdgeLoop {
  std::vector<int> arcs;
  //! The loop's nodes in order: for a closed loop the node between arcs[k] and arcs[k + 1]
  //! (arcs.size() of them); for an open loop also its two end nodes on the mesh boundary, first
  //! and last (arcs.size() + 1).
  std::vector<int> nodes;
  bool closed = false;
};

//! The edge loop through arc \p arc_index of \p layout on \p mesh: from each end of the arc on
//! through interior valence-4 nodes until it closes or ends at nodes on the mesh boundary.
//! \p topology: build_topology of the valid layout. \throw InvalidInputError naming the node
//! where the loop cannot go on: an interior node whose valence is not 4, a boundary node whose
//! valence is not 3 (after removal it must join exactly two arcs), a node passed twice, or a
//! dangling arc.
EdgeLoop find_edge_loop(const TriMesh& mesh, const Layout& layout, const LayoutTopology& topology,
                        int arc_index);

//! Removes the edge loop through arc \p arc_id of the valid \p layout: its arcs are deleted, and
//! at every node of the loop (its two boundary end nodes included) the two remaining arcs are
//! joined into one (paths concatenated; the joined arc keeps the smaller id and that arc's
//! direction; pinned when either was) and the node is deleted. Removing a loop that
//! insert_edge_loop inserted gives back the layout before the insertion (ids, ends and paths)
//! when the split arcs were routed back along their old paths. Traced output fields and patches
//! are dropped. \throw InvalidInputError when the layout is not valid, arc_id is unknown, or
//! find_edge_loop refuses.
Layout remove_edge_loop(const TriMesh& mesh, const Layout& layout, int arc_id);

}  // namespace qs
