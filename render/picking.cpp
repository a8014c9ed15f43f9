#include "render/picking.h"

#include <cmath>
#include <limits>

namespace qs::render {

void SurfacePicker::build(const TriMesh& mesh) {
  triangles_.assign(mesh.n_faces(), {});
  vertices_.assign(mesh.n_faces(), {{-1, -1, -1}});
  for (auto fh : mesh.faces()) {
    int k = 0;
    for (auto vh : mesh.fv_range(fh)) {
      if (k == 3) break;
      const auto& p = mesh.point(vh);
      triangles_[fh.idx()][k] = glm::dvec3(p[0], p[1], p[2]);
      vertices_[fh.idx()][k] = vh.idx();
      ++k;
    }
  }
}

std::optional<SurfaceHit> SurfacePicker::pick(const Ray& ray) const {
  // Moller-Trumbore, two-sided.
  double best = std::numeric_limits<double>::infinity();
  std::optional<SurfaceHit> hit;
  for (std::size_t f = 0; f < triangles_.size(); ++f) {
    const auto& t = triangles_[f];
    const glm::dvec3 e1 = t[1] - t[0];
    const glm::dvec3 e2 = t[2] - t[0];
    const glm::dvec3 p = glm::cross(ray.direction, e2);
    const double det = glm::dot(e1, p);
    if (std::abs(det) < 1e-300) continue;
    const double inv = 1.0 / det;
    const glm::dvec3 s = ray.origin - t[0];
    const double u = glm::dot(s, p) * inv;
    if (u < 0.0 || u > 1.0) continue;
    const glm::dvec3 q = glm::cross(s, e1);
    const double v = glm::dot(ray.direction, q) * inv;
    if (v < 0.0 || u + v > 1.0) continue;
    const double d = glm::dot(e2, q) * inv;
    if (d <= 0.0 || d >= best) continue;
    best = d;
    SurfaceHit h;
    h.face = static_cast<int>(f);
    h.bary = {1.0 - u - v, u, v};
    h.distance = d;
    h.position = ray.origin + d * ray.direction;
    int k = 0;
    for (int i = 1; i < 3; ++i)
      if (h.bary[i] > h.bary[k]) k = i;
    h.nearest_vertex = vertices_[f][k];
    hit = h;
  }
  return hit;
}

}  // namespace qs::render
