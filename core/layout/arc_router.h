// Arcs as edge paths of a working mesh: who occupies each vertex and edge, and a router that
// finds a path through vertices and edge midpoints and realizes it by splitting the crossed
// edges, so that an arc never needs the input triangulation to have room for it
// (docs/design.md, "Discretizing a layout").
#pragma once

#include <array>
#include <vector>

#include "core/mesh/working_mesh.h"

namespace qs {

//! Which node sits on each working-mesh vertex and which arc runs through each vertex and
//! edge. Indices are node and arc indices (positions in Layout::nodes / Layout::arcs), -1 for
//! free elements. The arrays follow the working mesh as it grows (sync); they are not valid
//! across WorkingMesh::compact().
class LayoutOccupancy {
 public:
  explicit LayoutOccupancy(const WorkingMesh& mesh);

  //! Grows the arrays to the working mesh's current vertex and edge counts (new elements free).
  void sync();
  //! Frees every element (and resizes the arrays to the working mesh).
  void clear();
  //! Marks node \p node on vertex \p v (-1 clears it).
  void set_node(int v, int node);
  //! Marks the interior vertices of \p path and all its edges as used by \p arc (-1 frees
  //! them). \pre consecutive path vertices are joined by an edge.
  void set_path(const std::vector<int>& path, int arc);

  int node_at(int v) const { return v < static_cast<int>(node_.size()) ? node_[v] : -1; }
  //! The arc whose path passes through \p v (not counting path ends), or -1.
  int arc_at(int v) const { return v < static_cast<int>(arc_.size()) ? arc_[v] : -1; }
  int arc_on_edge(int e) const { return e < static_cast<int>(edge_.size()) ? edge_[e] : -1; }
  //! A node or an arc occupies \p v.
  bool occupied(int v) const { return node_at(v) >= 0 || arc_at(v) >= 0; }

 private:
  const WorkingMesh& mesh_;
  std::vector<int> node_, arc_, edge_;
};

//! What to route: between two vertices (or from a vertex to the mesh boundary), optionally
//! along a guide polyline.
struct RouteRequest {
  int source = -1;  //!< working-mesh vertex where the path starts
  int target = -1;  //!< working-mesh vertex where it ends; -1: the nearest free boundary vertex
  //! 3D points the path should follow (from source to target), or empty. The path's cost grows
  //! with the distance from this polyline (corridor), and a guided search gives up on paths
  //! longer than max_length_factor × the guide's length (plus a few corridor widths).
  std::vector<Vec3> guide;
  //! Corridor half-width (length units); <= 0: twice the mean edge length around the source.
  double guide_width = 0;
  double max_length_factor = 3.0;
  //! Vertices next to other nodes cost this many times their length (each node's 1-ring is
  //! kept for its own arcs where possible).
  double foreign_ring_cost = 4.0;
  //! Passes that move the route's new vertices towards the straight line between their path
  //! neighbours (inside their input face or along their input edge); 0: midpoints as found.
  int straighten = 4;
};

//! Finds a path for \p request on \p mesh that avoids every occupied vertex (other than the
//! path's ends) and every arc edge, moving along free edges or across faces through the
//! midpoints of free interior edges, then realizes it: each midpoint becomes a vertex by
//! splitting its edge (WorkingMesh::split_edge, exact), and straightens it (RouteRequest::
//! straighten). Returns the vertex path (source first,
//! at least two vertices), or an empty path when no route exists (then nothing is changed, or,
//! rarely, a realization that could not join two of its vertices left its exact splits).
//! \p occupancy is synced but not marked: the caller marks the returned path.
//! \p splits, when given, is increased by the number of edges split; \p split_log, when given,
//! receives (a, b, m) for every edge (a, b) split at a new vertex m.
std::vector<int> route_arc(WorkingMesh& mesh, LayoutOccupancy& occupancy,
                           const RouteRequest& request, int* splits = nullptr,
                           std::vector<std::array<int, 3>>* split_log = nullptr);

//! The straight path on the surface from vertex \p source to vertex \p target: from each
//! vertex, the line towards the target (in the plane of the face whose corner wedge holds that
//! direction) crosses the opposite edge, which is split there (exact), or passes through an end
//! of that edge when the crossing is within \p snap (fraction of the edge) of it. Only free
//! vertices and free edges are used (\p occupancy, synced, not marked). Returns the vertex path
//! (source first), or an empty path when the line meets (or passes within the snap distance of)
//! an occupied vertex, an arc edge or the boundary, or strays (the splits made until then stay:
//! free refinement vertices, logged like route_arc's in \p split_log).
std::vector<int> route_straight(WorkingMesh& mesh, LayoutOccupancy& occupancy, int source,
                                int target, double snap = 0.15, int* splits = nullptr,
                                std::vector<std::array<int, 3>>* split_log = nullptr);

}  // namespace qs
