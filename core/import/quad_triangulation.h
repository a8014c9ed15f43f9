// Triangulating a quad mesh (each quad split refine × refine) and carrying vertex paths and a
// quad layout over to the triangulation.
#pragma once

#include <vector>

#include "core/import/base_complex.h"
#include "core/layout/layout.h"
#include "core/mesh/mesh.h"

namespace qs {

//! Most triangles triangulate_quads makes (2·refine²·#quads).
inline constexpr long long kMaxTriangulatedFaces = 20'000'000;

//! Triangulates a pure quad mesh, each quad first split refine × refine by bilinear
//! interpolation of its corners, each small quad then cut along its shorter diagonal.
//! Vertex order: the quad mesh's vertices (same indices), then refine − 1 points per edge (edge
//! order, running from the edge's first halfedge's from-vertex), then (refine − 1)² per face
//! (face order, row by row). Neighbouring quads share their edge points. 2·refine² triangles
//! per quad, in quad order.
//! \pre is_pure_quad(quads); refine >= 1; at most kMaxTriangulatedFaces triangles.
//! \throw InvalidInputError otherwise.
TriMesh triangulate_quads(const PolyMesh& quads, int refine = 1);

//! The vertex path on triangulate_quads(quads, refine) that runs along the quad-mesh vertex
//! path \p path (each quad edge becomes refine mesh edges).
//! \pre consecutive vertices of \p path are joined by quad-mesh edges.
std::vector<int> refine_quad_path(const PolyMesh& quads, int refine, const std::vector<int>& path);

//! The complex as a Layout on triangulate_quads(quads, refine): exact, no projection.
Layout layout_on_triangulation(const PolyMesh& quads, const QuadComplex& complex, int refine);

}  // namespace qs
