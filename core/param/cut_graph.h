// Cut graph and per-wedge variables of the seamless parameterization (docs/design.md,
// "Transitions and cut graph").
#pragma once

#include <array>
#include <vector>

#include "core/mesh/geometry.h"
#include "core/mesh/mesh.h"

namespace qs {

//! Rotation (quarter turns, 0..3) of the transition across edge e, going from the face
//! holding halfedge w→z to the face holding z→w: r = −σ·p_e mod 4 with σ = +1 iff w < z.
inline int step_rotation(int p_e, int w, int z) {
  const int r = (w < z ? -p_e : p_e) % 4;
  return r < 0 ? r + 4 : r;
}

//! R^r applied to (x, y): rotation by r·90°.
inline std::array<double, 2> rotate(int r, std::array<double, 2> a) {
  switch (((r % 4) + 4) % 4) {
    case 1:
      return {-a[1], a[0]};
    case 2:
      return {-a[0], -a[1]};
    case 3:
      return {a[1], -a[0]};
    default:
      return a;
  }
}

struct CutGraph {
  std::vector<char> cut;  //!< per edge (size #E): 1 if the edge is cut (interior only)
  int cut_edges = 0;
  //! Per face corner (size 3·#F, corner k of face f at 3f + k in GeometryCache::face_vertices
  //! order): the wedge (variable) it belongs to. Corners across non-cut edges share a wedge.
  std::vector<int> corner_wedge;
  int wedges = 0;
};

//! Cuts the mesh to a disk through all singular vertices: the complement of a spanning tree of
//! the dual graph over edges with p ≡ 0 (mod 4), with dangling branches retracted (never at a
//! singular vertex, never across an edge with p ≢ 0 mod 4).
//! \p singular: per vertex (size #V), 1 at cone vertices.
CutGraph build_cut_graph(const TriMesh& mesh, const GeometryCache& geometry,
                         const std::vector<int>& period_jump, const std::vector<char>& singular);

//! Corner index (0..2) of vertex v in face f. \pre v is a vertex of f.
inline int corner_of(const GeometryCache& g, int f, int v) {
  const auto& fv = g.face_vertices[f];
  return fv[0] == v ? 0 : (fv[1] == v ? 1 : 2);
}

}  // namespace qs
