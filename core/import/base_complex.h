// Base complex of a quad mesh: the patch layout formed by the separatrices of its irregular
// vertices (issue #6), or by all of its edges (a coarse cage). The result lives on the quad
// mesh's own vertices; quad_import.h turns it into a Layout on a triangle mesh.
#pragma once

#include <vector>

#include "core/mesh/mesh.h"

namespace qs {

//! A patch layout on a quad mesh: nodes on quad-mesh vertices, arcs as quad-edge chains.
//! Indices are positions in these vectors (node i has id i, arc a has id a on import).
struct QuadComplex {
  //! Quad-mesh vertex of each node, ascending (size #nodes).
  std::vector<int> node_vertex;
  struct Arc {
    int from = -1;          //!< node index
    int to = -1;            //!< node index (== from for a loop arc)
    std::vector<int> path;  //!< quad-mesh vertex chain, node_vertex[from] ... node_vertex[to]
  };
  std::vector<Arc> arcs;
  //! Number of patches: face components of the quad mesh separated by arc edges (computed
  //! independently of any triangle mesh, so tests can compare imports against it).
  int num_patches = 0;
  //! Per node: number of arc ends at it (size #nodes).
  std::vector<int> valence;
  //! Per node: the arc ends around its vertex in counter-clockwise order, as half-arc indices
  //! 2a (the arc leaves its `from` node) / 2a+1 (it arrives at its `to` node). For a boundary
  //! vertex the list starts after the exterior sector (LayoutTopology's convention).
  std::vector<std::vector<int>> node_half_arcs;
  //! Number of irregular vertices of the quad mesh (interior valence != 4, boundary valence
  //! != 3).
  int irregular_vertices = 0;
  //! False after coarsen_complex: arc paths are then walks on the quad mesh that may repeat
  //! vertices and share vertices with other arcs near merged nodes (fine as curves to
  //! transfer_complex, not as an exact layout on the quad mesh).
  bool simple_paths = true;
};

struct BaseComplexOptions {
  //! Use every edge as an arc and every vertex as a node (for coarse cages) instead of the
  //! separatrices.
  bool all_edges = false;
};

//! True when every face of \p mesh has exactly 4 vertices.
bool is_pure_quad(const PolyMesh& mesh);

//! One Catmull–Clark-style split without smoothing: every n-gon becomes n quads joining its
//! centroid, the midpoints of its edges and its corners. Vertex order of the result: the
//! original vertices (same indices and positions), then one midpoint per edge (in edge index
//! order), then one centroid per face (in face order). Faces: n per input face, in face order.
//! \pre \p mesh has no isolated vertices.
PolyMesh split_to_quads(const PolyMesh& mesh);

//! Computes the base complex of a pure quad mesh.
//!
//! Separatrices leave every irregular vertex along each incident edge and run "straight" on:
//! through an interior valence-4 vertex to the opposite edge, through a boundary valence-3
//! vertex along the boundary when they arrive along the boundary; they stop at irregular
//! vertices and where they reach the boundary from inside. The boundary itself always belongs
//! to the complex. Nodes are the irregular vertices and every vertex where 3 or more marked
//! edges meet (crossings, boundary hits); arcs are the maximal chains of marked edges between
//! nodes (loop arcs, from == to, can occur). A marked cycle without any node (a boundary loop
//! with no irregular vertex and no separatrix reaching it) gets a node at its smallest vertex.
//!
//! With options.all_edges every vertex is a node and every edge an arc (from its first
//! halfedge's from-vertex to its to-vertex), in edge order.
//!
//! Node order: ascending vertex index. Arc order: nodes in order, then their outgoing edges
//! counter-clockwise; deterministic for a given mesh.
//! \pre \p quads is pure quad (is_pure_quad) and manifold (load_poly_mesh checks this).
//! \throw InvalidInputError if a face is not a quad, or (without all_edges) the mesh has no
//!        irregular vertex and no boundary, so there are no separatrices ("... use
//!        --all-edges").
QuadComplex base_complex(const PolyMesh& quads, const BaseComplexOptions& options = {});

}  // namespace qs
