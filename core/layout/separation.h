// Room between the arcs of a layout on a working mesh: splits where two arcs, an arc and a
// node, or two nodes come so close that the patch between them has no interior vertex, and
// where a triangle has all its corners on one arc (docs/design.md, "Separation").
#pragma once

#include <vector>

#include "core/layout/layout.h"
#include "core/mesh/working_mesh.h"

namespace qs {

//! Per working-mesh vertex, the arcs (indices into layout.arcs) that run through it: a node's
//! vertex carries all the node's arcs, a path's interior vertices its arc, a dangling arc's
//! boundary end its arc. Size #V of \p mesh.
std::vector<std::vector<int>> arcs_per_vertex(const TriMesh& mesh, const Layout& layout);

//! Splits edges at their midpoints (exact, WorkingMesh::split_edge) until
//! - no edge that is not an arc edge joins two vertices on different arcs (the node two arcs
//!   share counts for both) where both triangles on that edge have all their corners on arcs
//!   (a strip between two arcs, or an arc and a node, without an interior vertex);
//! - no edge joins two nodes that no arc joins;
//! - no triangle has all three corners on one arc (it would map to a segment).
//! Each split adds a vertex on no arc and touches no arc edge, so arc paths stay valid and the
//! process ends after at most one split per offending edge. Returns the number of splits.
//! \pre layout's node vertices and arc paths are valid on mesh.mesh().
int separate_layout(WorkingMesh& mesh, const Layout& layout);

}  // namespace qs
