// Fitting a quad cage onto a triangle mesh: smoothing, closest-point projection onto faces
// facing the cage's way, splitting (steps of cage_layout, core/import/cage.h).
#pragma once

#include "core/mesh/mesh.h"

namespace qs {

struct CageFitOptions {
  //! Uniform Laplacian smoothing rounds of the voxel cage in 3D before the first projection
  //! (removes the staircase; the projection undoes the shrinking).
  int presmoothing = 3;
  //! Rounds of tangential spring relaxation (cage edges towards their mean length, quad
  //! diagonals towards √2 times it, moved within the surface's tangent plane), each followed
  //! by a closest-point re-projection onto faces facing the same way.
  int iterations = 30;
  double step = 0.5;  //!< fraction of the move towards the neighbours' mean per round
};

//! Moves the cage's vertices onto \p mesh: presmoothing, closest-point projection, then
//! tangential smoothing + re-projection. Returns the number of folded quads afterwards (the
//! normal of the projected quad points against the mesh normal at its corners).
int fit_cage(PolyMesh& cage, const TriMesh& mesh, const CageFitOptions& options = {});

//! Splits every quad of a fitted cage into 4 (split_to_quads: edge midpoints and face
//! centroids, original vertices kept with their indices) and moves the new vertices onto
//! \p mesh (closest point on a face facing the same way as the split cage at the vertex).
//! Straight cage edges cut across concave corners and narrow gaps between their end vertices;
//! the split ones follow the surface, so the transfer's closest-point samples of an arc stay
//! on the arc's own side. The base complex keeps its nodes (the new vertices are regular).
//! \pre is_pure_quad(cage).
void refine_fitted_cage(PolyMesh& cage, const TriMesh& mesh);

//! Area-weighted (Newell) normal of a polygon-mesh vertex: the sum of the cross products of the
//! edges of its faces (not normalized; zero for an isolated vertex).
Vec3 cage_vertex_normal(const PolyMesh& cage, OpenMesh::VertexHandle v);

//! \p iterations rounds of umbrella smoothing of all vertices of \p quads (each to its
//! neighbours' mean), each round followed by a closest-point projection onto the faces of
//! \p mesh that face the same way as \p quads at the vertex (cage_vertex_normal), within three
//! mean edge lengths. Nothing happens for iterations <= 0 or an empty mesh.
void relax_on_surface(PolyMesh& quads, const TriMesh& mesh, int iterations);

}  // namespace qs
