// CPU picking: rays against the mesh surface (no GL; works on the same data the GPU draws).
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "core/mesh/mesh.h"
#include "render/camera.h"

namespace qs::render {

struct SurfaceHit {
  int face = -1;
  //! Barycentric coordinates w.r.t. the face's vertices in OpenMesh face-vertex order.
  std::array<double, 3> bary{{1.0 / 3, 1.0 / 3, 1.0 / 3}};
  double distance = 0.0;    //!< along the ray
  int nearest_vertex = -1;  //!< the face vertex with the largest barycentric coordinate
  glm::dvec3 position{0.0};
};

//! Ray casting against a triangle mesh. Keeps a flat copy of the triangles so that picks
//! during drags touch contiguous memory (about 1 ms per 100K faces; no BVH needed for
//! interactive clicks).
class SurfacePicker {
 public:
  void build(const TriMesh& mesh);
  //! Nearest hit (both sides of triangles count), or nothing.
  std::optional<SurfaceHit> pick(const Ray& ray) const;

 private:
  std::vector<std::array<glm::dvec3, 3>> triangles_;
  std::vector<std::array<int, 3>> vertices_;
};

}  // namespace qs::render
