// A point on the surface of a triangle mesh, as a face and barycentric coordinates.
#pragma once

#include <array>

namespace qs {

//! A point on the surface: a face and barycentric coordinates w.r.t. its 3 vertices
//! (in OpenMesh face-vertex order, i.e. the file order of the face's corners).
struct SurfacePoint {
  int face = -1;
  std::array<double, 3> bary{{1.0 / 3, 1.0 / 3, 1.0 / 3}};
};

}  // namespace qs
