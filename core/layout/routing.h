// Routing of arcs onto mesh edges: shortest paths that avoid other arcs and nodes.
#pragma once

#include <vector>

#include "core/layout/layout.h"
#include "core/mesh/mesh.h"

namespace qs {

//! The vertex of \p p's face with the largest barycentric coordinate (ties: the first corner
//! in face-vertex order).
//! \throw InvalidInputError if the face index is out of range, or the barycentrics are not
//!        finite, are below -1e-9, or do not sum to 1 within 1e-6.
int snap_to_vertex(const TriMesh& mesh, const SurfacePoint& p);

//! Blocked elements for routing: vertices and edges no new path may use.
struct RoutingObstacles {
  std::vector<char> vertex_blocked;  //!< size #V
  std::vector<char> edge_blocked;    //!< size #E
};

//! Marks every vertex and edge used by the existing arc paths and every node vertex.
RoutingObstacles obstacles_of_layout(const TriMesh& mesh, const Layout& layout);

//! Shortest edge path (Euclidean edge lengths; A* with the straight-line bound) from \p source to
//! \p target, not using blocked edges, and not passing through blocked vertices (source and target
//! may be blocked). Returns the vertex path (source first): {source} when source == target, empty
//! if no path exists or a vertex index is out of range.
std::vector<int> shortest_path(const TriMesh& mesh, int source, int target,
                               const RoutingObstacles& obstacles);

//! Shortest path (same rules) from \p source to the nearest unblocked boundary vertex other
//! than \p source (for dangling arcs). Empty when none is reachable (e.g. a closed mesh).
std::vector<int> shortest_path_to_boundary(const TriMesh& mesh, int source,
                                           const RoutingObstacles& obstacles);

//! Routes every arc that has `points` but no `path`. Its from-node vertex, each point and its
//! to-node vertex are snapped and joined by shortest paths avoiding all other arcs and nodes
//! and the arc's own earlier part; consecutive duplicates are dropped. A point is snapped to the
//! heaviest corner of its face that the route may use (normally the largest barycentric;
//! corners on other arcs or nodes are passed over). A dangling arc continues from its last point
//! to the nearest reachable boundary vertex (or ends at the last point if that is a boundary
//! vertex). Arcs are routed in file order; each routed arc becomes an obstacle for the next.
//! Arcs that fail keep an empty path; the others are routed.
//! \throw InvalidInputError naming every arc id that could not be routed, with the reason
//!        ("cannot route arcs 4, 9: arc 4: no path avoiding other arcs between vertices ...").
void route_layout(const TriMesh& mesh, Layout& layout);

}  // namespace qs
