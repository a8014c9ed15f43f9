#include "core/import/cage_fit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "core/import/base_complex.h"
#include "core/mesh/closest_point.h"

namespace qs {

namespace {

using VH = OpenMesh::VertexHandle;

// Mean edge length of a polygon mesh (0 without edges).
double mean_edge_length(const PolyMesh& m) {
  double sum = 0;
  for (const auto e : m.edges()) sum += m.calc_edge_length(e);
  return sum / std::max<size_t>(1, m.n_edges());
}

// Mean position of v's neighbours (v itself when it has none).
Vec3 neighbour_mean(const PolyMesh& m, VH v) {
  Vec3 sum(0, 0, 0);
  int count = 0;
  for (const auto w : m.vv_range(v)) {
    sum += m.point(w);
    ++count;
  }
  return count ? sum / count : m.point(v);
}

// Closest points restricted to faces whose normal agrees with a reference direction, among
// the faces within a search radius (a uniform hash grid of face bounding boxes); falls back
// to the unrestricted closest point. Keeps cage vertices on their own side of thin parts.
class SidedProjector {
 public:
  SidedProjector(const TriMesh& mesh, double cell) : mesh_(mesh), tree_(mesh), cell_(cell) {
    normal_.resize(mesh.n_faces());
    corners_.resize(mesh.n_faces());
    const double inf = std::numeric_limits<double>::infinity();
    lo_ = Vec3(inf, inf, inf);
    Vec3 hi(-inf, -inf, -inf);
    for (const auto v : mesh.vertices()) {
      lo_.minimize(mesh.point(v));
      hi.maximize(mesh.point(v));
    }
    for (int a = 0; a < 3; ++a)
      dims_[a] = std::max(1, static_cast<int>(std::ceil((hi[a] - lo_[a]) / cell_)) + 1);
    buckets_.assign(static_cast<size_t>(dims_[0]) * dims_[1] * dims_[2], {});
    for (const auto f : mesh.faces()) {
      int k = 0;
      Vec3 blo(inf, inf, inf), bhi(-inf, -inf, -inf);
      for (const auto v : mesh.fv_range(f)) {
        corners_[f.idx()][k++] = mesh.point(v);
        blo.minimize(mesh.point(v));
        bhi.maximize(mesh.point(v));
      }
      Vec3 n = mesh.calc_face_normal(f);
      const double len = n.norm();
      normal_[f.idx()] = len > 0 ? n / len : Vec3(0, 0, 0);
      const auto a = bucket_of(blo), b = bucket_of(bhi);
      for (int z = a[2]; z <= b[2]; ++z)
        for (int y = a[1]; y <= b[1]; ++y)
          for (int x = a[0]; x <= b[0]; ++x) buckets_[index(x, y, z)].push_back(f.idx());
    }
    stamp_.assign(mesh.n_faces(), 0);
  }

  const Vec3& face_normal(int f) const { return normal_[f]; }

  //! Closest point on a face within \p radius whose normal has a positive dot product with
  //! \p reference (unrestricted closest point when there is none).
  ClosestPoint project(const Vec3& p, const Vec3& reference, double radius) {
    const ClosestPoint nearest = tree_.closest(p);
    if (OpenMesh::dot(normal_[nearest.face], reference) > 0) return nearest;
    ClosestPoint best;
    best.distance = std::numeric_limits<double>::infinity();
    const auto a = bucket_of(p - Vec3(radius, radius, radius));
    const auto b = bucket_of(p + Vec3(radius, radius, radius));
    ++current_;
    for (int z = a[2]; z <= b[2]; ++z) {
      for (int y = a[1]; y <= b[1]; ++y) {
        for (int x = a[0]; x <= b[0]; ++x) {
          for (int f : buckets_[index(x, y, z)]) {
            if (stamp_[f] == current_) continue;
            stamp_[f] = current_;
            if (OpenMesh::dot(normal_[f], reference) <= 0) continue;
            const auto& c = corners_[f];
            const TrianglePoint tp = closest_point_on_triangle(p, c[0], c[1], c[2]);
            if (tp.distance < best.distance) {
              best.distance = tp.distance;
              best.point = tp.point;
              best.face = f;
              best.bary = tp.bary;
            }
          }
        }
      }
    }
    if (best.face < 0 || best.distance > radius) return nearest;
    return best;
  }

 private:
  std::array<int, 3> bucket_of(const Vec3& p) const {
    std::array<int, 3> b;
    for (int a = 0; a < 3; ++a)
      b[a] = std::clamp(static_cast<int>(std::floor((p[a] - lo_[a]) / cell_)), 0, dims_[a] - 1);
    return b;
  }
  size_t index(int x, int y, int z) const {
    return static_cast<size_t>(x) +
           static_cast<size_t>(dims_[0]) * (y + static_cast<size_t>(dims_[1]) * z);
  }

  const TriMesh& mesh_;
  ClosestPointTree tree_;
  double cell_;
  Vec3 lo_;
  std::array<int, 3> dims_{{1, 1, 1}};
  std::vector<std::vector<int>> buckets_;
  std::vector<Vec3> normal_;
  std::vector<std::array<Vec3, 3>> corners_;
  std::vector<int> stamp_;
  int current_ = 0;
};

}  // namespace

Vec3 cage_vertex_normal(const PolyMesh& cage, VH v) {
  Vec3 n(0, 0, 0);
  for (const auto f : cage.vf_range(v)) {
    for (const auto h : cage.fh_range(f)) {
      n += OpenMesh::cross(cage.point(cage.from_vertex_handle(h)),
                           cage.point(cage.to_vertex_handle(h)));
    }
  }
  return n;
}

void refine_fitted_cage(PolyMesh& cage, const TriMesh& mesh) {
  const size_t old_vertices = cage.n_vertices();
  if (old_vertices == 0) return;
  const double mean_edge = mean_edge_length(cage);
  cage = split_to_quads(cage);
  SidedProjector projector(mesh, 0.5 * mean_edge);
  std::vector<Vec3> normal(cage.n_vertices());
  for (const auto v : cage.vertices()) normal[v.idx()] = cage_vertex_normal(cage, v);
  for (const auto v : cage.vertices()) {
    if (static_cast<size_t>(v.idx()) < old_vertices) continue;
    cage.set_point(v, projector.project(cage.point(v), normal[v.idx()], 1.5 * mean_edge).point);
  }
}

void relax_on_surface(PolyMesh& quads, const TriMesh& mesh, int iterations) {
  if (iterations <= 0 || quads.n_vertices() == 0) return;
  const double mean_edge = mean_edge_length(quads);
  SidedProjector projector(mesh, mean_edge);
  std::vector<Vec3> next(quads.n_vertices());
  for (int it = 0; it < iterations; ++it) {
    for (const auto v : quads.vertices()) next[v.idx()] = neighbour_mean(quads, v);
    for (const auto v : quads.vertices()) {
      const Vec3 n = cage_vertex_normal(quads, v);
      quads.set_point(v, projector.project(next[v.idx()], n, 3.0 * mean_edge).point);
    }
  }
}

int fit_cage(PolyMesh& cage, const TriMesh& mesh, const CageFitOptions& options) {
  const size_t nv = cage.n_vertices();
  if (nv == 0) return 0;
  const double mean_edge = mean_edge_length(cage);
  SidedProjector projector(mesh, mean_edge);
  std::vector<Vec3> cage_normal(nv), next(nv);
  for (const auto v : cage.vertices()) cage_normal[v.idx()] = cage_vertex_normal(cage, v);
  std::vector<int> face(nv, -1);
  for (int it = 0; it < options.presmoothing; ++it) {
    for (const auto v : cage.vertices()) {
      next[v.idx()] = cage.point(v) + options.step * (neighbour_mean(cage, v) - cage.point(v));
    }
    for (const auto v : cage.vertices()) cage.set_point(v, next[v.idx()]);
  }
  const double radius = 3.0 * mean_edge;
  for (const auto v : cage.vertices()) {
    const ClosestPoint cp = projector.project(cage.point(v), cage_normal[v.idx()], radius);
    cage.set_point(v, cp.point);
    face[v.idx()] = cp.face;
  }
  // Tangential spring relaxation: every cage edge pulls/pushes towards the mean edge length,
  // every quad diagonal towards √2 times it (keeps quads from collapsing onto a line).
  const double rest = mean_edge_length(cage);
  auto spring = [&](const Vec3& from, const Vec3& to, double length) {
    const Vec3 d = to - from;
    const double l = d.norm();
    return l > 1e-12 * rest ? d * ((l - length) / l) : Vec3(0, 0, 0);
  };
  for (int it = 0; it < options.iterations; ++it) {
    for (const auto v : cage.vertices()) {
      const Vec3& p = cage.point(v);
      Vec3 force(0, 0, 0);
      int count = 0;
      for (const auto h : cage.voh_range(v)) {
        force += spring(p, cage.point(cage.to_vertex_handle(h)), rest);
        ++count;
        if (cage.is_boundary(h)) continue;
        // Diagonal of the quad left of h.
        const auto diag = cage.to_vertex_handle(cage.next_halfedge_handle(h));
        force += 0.5 * spring(p, cage.point(diag), std::sqrt(2.0) * rest);
      }
      const Vec3& n = projector.face_normal(face[v.idx()]);
      Vec3 d = count ? force / count : force;
      d -= OpenMesh::dot(d, n) * n;
      next[v.idx()] = p + options.step * d;
    }
    for (const auto v : cage.vertices()) {
      const ClosestPoint cp =
          projector.project(next[v.idx()], projector.face_normal(face[v.idx()]), radius);
      cage.set_point(v, cp.point);
      face[v.idx()] = cp.face;
    }
  }
  int folded = 0;
  for (const auto f : cage.faces()) {
    Vec3 quad_normal(0, 0, 0), surface_normal(0, 0, 0);
    for (const auto h : cage.fh_range(f)) {
      quad_normal += OpenMesh::cross(cage.point(cage.from_vertex_handle(h)),
                                     cage.point(cage.to_vertex_handle(h)));
      surface_normal += projector.face_normal(face[cage.to_vertex_handle(h).idx()]);
    }
    folded += OpenMesh::dot(quad_normal, surface_normal) <= 0;
  }
  return folded;
}

}  // namespace qs
