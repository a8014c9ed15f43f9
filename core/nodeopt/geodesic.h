// Straightest geodesics on a triangle mesh [PS98] and the node-Voronoi safeguard
// (paper §6.1.1, §7.2; docs/design.md, "Straightest geodesics").
#pragma once

#include <functional>
#include <vector>

#include "core/layout/layout.h"
#include "core/mesh/mesh.h"

namespace qs {

struct GeodesicTrace {
  SurfacePoint end;            //!< where the trace stopped (face of the traced mesh)
  Vec3 end_position{0, 0, 0};  //!< the same point in 3D (mesh units)
  double length = 0;           //!< length actually traced (mesh units)
  bool hit_boundary = false;   //!< stopped at the mesh boundary
  bool truncated = false;      //!< stopped before a blocked face
  std::vector<int> faces;      //!< faces visited, in order
};

//! Traces a straightest geodesic of length \p length (mesh units) from \p start in the 3D
//! direction \p direction (projected into the start face; at a vertex start, into the incident
//! face whose corner wedge contains it). Inside a face the path is straight; at an edge the next
//! face is unfolded; through a vertex it leaves into the wedge containing the projected
//! direction (docs/design.md, "Straightest geodesics"). It stops at the boundary, and before
//! entering a face for which \p blocked_face returns true (the point is then on the shared
//! edge or vertex).
//! \pre start.face is a valid face with barycentrics in [0, 1] summing to 1; length ≥ 0.
GeodesicTrace trace_straightest_geodesic(const TriMesh& mesh, const SurfacePoint& start,
                                         const Vec3& direction, double length,
                                         const std::function<bool(int)>& blocked_face = {});

//! 3D position of a surface point of \p mesh.
Vec3 surface_position(const TriMesh& mesh, const SurfacePoint& p);

//! A surface point at vertex \p v: an incident face with barycentric 1 at that corner.
SurfacePoint vertex_surface_point(const TriMesh& mesh, int v);

//! Multi-source Dijkstra over mesh edges (Euclidean lengths): for every vertex the index into
//! \p sources of the nearest source vertex (-1 when unreachable). Size #V.
std::vector<int> node_voronoi_cells(const TriMesh& mesh, const std::vector<int>& sources);

}  // namespace qs
