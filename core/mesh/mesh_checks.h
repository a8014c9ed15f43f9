// Topological and geometric checks of meshes (used by load_mesh and by the pipeline).
#pragma once

#include <functional>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/mesh/mesh_io.h"

namespace qs {

//! Builds a triangle mesh from a soup, recording every problem in \p report (it never throws).
//! All soup vertices are added first in order (vertex idx() == soup index, unreferenced ones
//! included); faces follow in soup order, polygons expanding in place into the triangles of
//! triangulate_polygon (or, with options.triangulate == false, being reported in
//! non_triangle_faces).
//! Checks, all from the soup or the built mesh, never silently repaired:
//! - bad_index_faces: an index outside [0, #points).
//! - nonfinite_vertices: NaN or infinite coordinates.
//! - out_of_range_vertices: a finite coordinate of magnitude above kMaxCoordinateMagnitude.
//!   Faces with a non-finite or out-of-range corner are not judged geometrically (not
//!   degenerate, not untriangulable; polygons are split into a fan from their first corner).
//! - degenerate_faces: a repeated vertex index (not added), or zero area, i.e.
//!   area <= 1e-14 * (bounding-box diagonal of the in-range points)^2 (still added), for the
//!   polygon or one of its triangles. Real slivers stay valid (smallest area / diagonal^2
//!   among the shared meshes: bunny.off 7e-9, block.off 1e-7); collinear corners give 0 or
//!   rounding noise up to ~1e-15.
//! - untriangulable_faces: a polygon with non-zero area that triangulate_polygon cannot split
//!   (still added, as a fan from its first corner).
//! - dropped_faces / drop_reasons: add_face refused the face (an edge that already has two
//!   faces, an edge already used in the same direction, a complex vertex) or it repeats an
//!   earlier face's vertex cycle in either direction.
//! - nonmanifold_vertices: the soup faces around the vertex do not form one fan (their link
//!   is not a single path or cycle), whether OpenMesh accepted them (two fans touching at a
//!   vertex, seen by is_manifold()) or refused some; plus every vertex !is_manifold().
//! - unreferenced_vertices: used by no soup face.
//! Then count_topology() fills the counts.
//! \pre \p report is default-constructed except for path (lists are appended to).
TriMesh build_tri_mesh(const PolygonSoup& soup, MeshReport& report, const LoadMeshOptions& options);

//! Same for a polygon mesh (faces are kept as they are).
PolyMesh build_poly_mesh(const PolygonSoup& soup, MeshReport& report);

//! Fills the counts of \p report (vertices, faces, edges, components, boundary loops, Euler
//! characteristic, genus) from \p mesh. Components are vertex-connected sets of faces; the
//! Euler characteristic counts only vertices that belong to a face (isolated ones are reported
//! as unreferenced instead); genus = (2 * components - boundary_loops - chi) / 2.
//! Instantiated for TriMesh and PolyMesh.
template <typename MeshT>
void count_topology(const MeshT& mesh, MeshReport& report);

//! Boundary loops as vertex index cycles, each ordered with the interior on the left
//! (i.e. along the non-boundary halfedges of the boundary edges). Each loop starts at its
//! smallest vertex index and the loops are sorted, so the result depends only on the mesh.
std::vector<std::vector<int>> boundary_loops(const TriMesh& mesh);

//! Spanning forest of the dual graph by BFS from face 0 (then every unreached face), crossing
//! only interior edges for which \p crossable(edge index) is true. Returns a flag per edge
//! (size #E): 1 for the tree's edges.
std::vector<char> dual_spanning_tree(const TriMesh& mesh,
                                     const std::function<bool(int)>& crossable);

//! Connected component id per face (size #F) and the number of components. Faces sharing a
//! vertex are connected; ids are numbered in order of each component's first face.
std::vector<int> face_components(const TriMesh& mesh, int* count = nullptr);

}  // namespace qs
