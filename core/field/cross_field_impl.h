// Private to core/field (included by the cross field files only; not part of the API): the
// constants and edge test the parts of CrossFieldSolver share (docs/design.md, "Cross field"):
// - cross_field.cpp: setup, the matrix and its factorizations, the solve, update_layout, and
//   the free functions on fields (matching, indices, directions, constraint summaries);
// - cross_field_clusters.cpp: the constraint clusters (aligned boundary turns, propagation
//   of the relative rotations), their warm start and the reference field's rotation;
// - cross_field_conflicts.cpp: releasing the constraints that contradict the layout (drop
//   passes, the structural pass, the deviation release).
#pragma once

#include <cmath>

#include "core/mesh/geometry.h"

namespace qs {

namespace cross_field_detail {

// A quarter turn (radians).
inline constexpr double kQuarter = M_PI / 2;

// Edge \p e of \p g has a face on both sides.
inline bool interior(const GeometryCache& g, int e) {
  return g.edge_face_i[e] >= 0 && g.edge_face_j[e] >= 0;
}

}  // namespace cross_field_detail

}  // namespace qs
