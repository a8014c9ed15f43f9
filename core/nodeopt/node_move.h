// Moving layout nodes on a working mesh (docs/design.md, "Moving a node"): a node goes to
// exactly the surface point its step reaches, through its own vertex. Inside its input face (or
// along its input edge) that vertex just moves; elsewhere a vertex is inserted at the point and
// the node's arcs are re-routed from it. Input vertices never move.
#pragma once

#include <vector>

#include "core/layout/arc_router.h"
#include "core/layout/layout.h"
#include "core/mesh/working_mesh.h"

namespace qs {

//! A layout on a working mesh while its nodes move: node vertices and arc paths are
//! working-mesh indices, and the occupancy mirrors them.
struct MeshLayout {
  WorkingMesh mesh;
  Layout layout;
};

//! How a node move was realized.
enum class NodeMove {
  kRefused,   //!< nothing changed (no route, a changed cyclic order of arcs, a blocked point)
  kGeometry,  //!< the node's vertex moved (same connectivity)
  kRelaid,    //!< a new vertex carries the node and its arcs were re-routed (new connectivity)
  //! The move failed and an old path could not be restored (an edge of it was flipped away):
  //! the state is invalid and must be discarded.
  kBroken,
};

struct NodeMoveOptions {
  //! Each arc keeps its old path from the first vertex (at least min_splice edges from the node)
  //! that lies at least this many step lengths from the new position; before it, it is
  //! re-routed.
  double splice_factor = 1.5;
  //! Each arc is re-routed at least up to its min_splice-th vertex from the node.
  size_t min_splice = 1;
};

//! The arcs of layout.arcs incident to each node (indices), with the end at the node (0: the
//! arc's `from` end, 1: its `to` end), in file order. Self-loops appear twice.
struct NodeArcs {
  std::vector<std::vector<std::pair<int, int>>> arcs;  //!< per node: (arc index, end)
};
NodeArcs node_arcs(const Layout& layout);

//! The arcs leaving working-mesh vertex \p v in counter-clockwise order, as (arc index, end)
//! pairs of \p incident, read from the first edge of each arc's path at v.
std::vector<std::pair<int, int>> arcs_around(const TriMesh& mesh, const Layout& layout, int v,
                                             const std::vector<std::pair<int, int>>& incident);

//! Moves node \p node (index into layout.nodes) to the input surface point \p target.
//! \p occupancy must mirror \p state; it is kept up to date. Vertices that the move freed
//! (the old node vertex and the old first parts of its arcs, when re-routed) are appended to
//! \p freed (cleanup candidates; some may be input vertices). A refused move may leave exact
//! splits in the mesh (free refinement vertices, and split vertices on the old paths, which
//! then run through them), nothing else; a broken one leaves an invalid state.
NodeMove move_node(MeshLayout& state, LayoutOccupancy& occupancy, const NodeArcs& arcs, int node,
                   const SurfacePoint& target, std::vector<int>& freed,
                   const NodeMoveOptions& options = {});

//! Removes the free refinement vertices among \p candidates (no node, not on an arc), then
//! splits where arcs need room (separate_layout), and compacts the mesh, renumbering the
//! layout's vertices. Returns the number of vertices removed.
int tidy_mesh_layout(MeshLayout& state, const std::vector<int>& candidates);

//! Rebuilds an occupancy of \p state from scratch.
void fill_occupancy(const MeshLayout& state, LayoutOccupancy& occupancy);

}  // namespace qs
