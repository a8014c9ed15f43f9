#include "core/field/curvature.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace qs {

int FieldConstraints::count(ConstraintKind k) const {
  return static_cast<int>(std::count(kind.begin(), kind.end(), k));
}

namespace {

// Signed dihedral angle of an interior edge: positive where the surface is convex.
double signed_dihedral(const TriMesh& mesh, const GeometryCache& g, int e) {
  const int i = g.edge_face_i[e], j = g.edge_face_j[e];
  if (i < 0 || j < 0) return 0.0;
  const Vec3& ni = g.face_normal[i];
  const Vec3& nj = g.face_normal[j];
  const auto [a, b] = g.edge_vertices[e];
  Vec3 t = mesh.point(mesh.vertex_handle(b)) - mesh.point(mesh.vertex_handle(a));
  t.normalize();
  // Face i holds a→b, so its interior is on the left of t; rotating ni to nj about t is
  // positive for a convex edge.
  return std::atan2((ni % nj) | t, ni | nj);
}

}  // namespace

Curvature compute_curvature(const TriMesh& mesh, const GeometryCache& g,
                            const CurvatureOptions& opt) {
  const int nv = g.n_vertices, nf = g.n_faces;
  // Per-vertex tensor: Σ over incident edges of β_e·(|e|/2)·ê êᵀ, with its area A_v/3 share.
  std::vector<Eigen::Matrix3d> tensor(nv, Eigen::Matrix3d::Zero());
  std::vector<double> area(nv, 0.0);
  for (int e = 0; e < g.n_edges; ++e) {
    const double beta = signed_dihedral(mesh, g, e);
    if (beta == 0.0) continue;
    const auto [a, b] = g.edge_vertices[e];
    const Vec3 d = mesh.point(mesh.vertex_handle(b)) - mesh.point(mesh.vertex_handle(a));
    const double len = d.norm();
    if (len == 0) continue;
    const Eigen::Vector3d u(d[0] / len, d[1] / len, d[2] / len);
    const Eigen::Matrix3d m = beta * 0.5 * len * (u * u.transpose());
    tensor[a] += m;
    tensor[b] += m;
  }
  for (int f = 0; f < nf; ++f)
    for (int v : g.face_vertices[f]) area[v] += g.face_area[f] / 3.0;

  // Smooth over rings: vertex neighbourhoods grown by BFS up to `rings` edges.
  std::vector<Eigen::Matrix3d> smooth_t = tensor;
  std::vector<double> smooth_a = area;
  for (int r = 1; r < opt.rings; ++r) {
    std::vector<Eigen::Matrix3d> nt(nv, Eigen::Matrix3d::Zero());
    std::vector<double> na(nv, 0.0);
    for (auto v : mesh.vertices()) {
      Eigen::Matrix3d t = smooth_t[v.idx()];
      double a = smooth_a[v.idx()];
      int count = 1;
      for (auto w : mesh.vv_range(v)) {
        t += smooth_t[w.idx()];
        a += smooth_a[w.idx()];
        ++count;
      }
      nt[v.idx()] = t / count;
      na[v.idx()] = a / count;
    }
    smooth_t.swap(nt);
    smooth_a.swap(na);
  }

  Curvature c;
  c.k_max.resize(nf);
  c.k_min.resize(nf);
  c.dir_max.resize(nf);
  c.reliable.assign(nf, 0);
  std::vector<double> magnitude(nf);
  for (int f = 0; f < nf; ++f) {
    Eigen::Matrix3d t = Eigen::Matrix3d::Zero();
    double a = 0;
    for (int v : g.face_vertices[f]) t += smooth_t[v], a += smooth_a[v];
    if (a > 0) t /= a;
    const Vec3& r = g.face_frame[f];
    const Vec3 s = g.face_normal[f] % r;
    const Eigen::Vector3d er(r[0], r[1], r[2]), es(s[0], s[1], s[2]);
    Eigen::Matrix2d t2;
    t2 << er.dot(t * er), er.dot(t * es), es.dot(t * er), es.dot(t * es);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(t2);
    // The eigenvector of the largest |eigenvalue| is the direction of least bending (edges
    // along it bend the most): the curvature across it is that eigenvalue.
    const Eigen::Vector2d lam = eig.eigenvalues();
    const int big = std::abs(lam(0)) > std::abs(lam(1)) ? 0 : 1;
    const Eigen::Vector2d along = eig.eigenvectors().col(big);
    // Curvature in direction `along` is lam(1-big); across it (perpendicular) lam(big).
    const double k_along = lam(1 - big), k_across = lam(big);
    const Vec3 dir_along = along(0) * r + along(1) * s;
    const Vec3 dir_across = g.face_normal[f] % dir_along;
    if (k_across >= k_along) {
      c.k_max[f] = k_across, c.k_min[f] = k_along, c.dir_max[f] = dir_across;
    } else {
      c.k_max[f] = k_along, c.k_min[f] = k_across, c.dir_max[f] = dir_along;
    }
    magnitude[f] = std::max(std::abs(c.k_max[f]), std::abs(c.k_min[f]));
  }
  if (nf == 0) return c;
  std::vector<double> sorted = magnitude;
  const size_t q = static_cast<size_t>(0.95 * (nf - 1));
  std::nth_element(sorted.begin(), sorted.begin() + q, sorted.end());
  const double s95 = sorted[q];
  if (s95 <= 0) return c;
  for (int f = 0; f < nf; ++f) {
    const double diff = c.k_max[f] - c.k_min[f];
    const double sum = std::abs(c.k_max[f]) + std::abs(c.k_min[f]);
    c.reliable[f] = diff >= opt.min_anisotropy * s95 && diff >= opt.min_ratio * sum;
  }
  // Drop small regions (noise).
  std::vector<int> region(nf, -1);
  std::vector<int> stack, members;
  for (int f0 = 0; f0 < nf; ++f0) {
    if (!c.reliable[f0] || region[f0] >= 0) continue;
    members.clear();
    stack.assign(1, f0);
    region[f0] = f0;
    while (!stack.empty()) {
      const int f = stack.back();
      stack.pop_back();
      members.push_back(f);
      for (auto h : mesh.fh_range(mesh.face_handle(f))) {
        const auto opp = mesh.opposite_halfedge_handle(h);
        if (mesh.is_boundary(opp)) continue;
        const int f2 = mesh.face_handle(opp).idx();
        if (c.reliable[f2] && region[f2] < 0) region[f2] = f0, stack.push_back(f2);
      }
    }
    if (static_cast<int>(members.size()) < opt.min_region_faces)
      for (int f : members) c.reliable[f] = 0;
  }
  c.reliable_faces = static_cast<int>(std::count(c.reliable.begin(), c.reliable.end(), 1));
  return c;
}

std::vector<char> sharp_edges(const TriMesh& mesh, const GeometryCache& g, double sharp_angle_deg,
                              const Layout* layout) {
  std::vector<char> sharp(g.n_edges, 0);
  const double threshold = sharp_angle_deg * M_PI / 180.0;
  for (int e = 0; e < g.n_edges; ++e) {
    const int i = g.edge_face_i[e], j = g.edge_face_j[e];
    if (i < 0 || j < 0) continue;
    const double angle = std::acos(std::clamp(g.face_normal[i] | g.face_normal[j], -1.0, 1.0));
    if (angle > threshold) sharp[e] = 1;
  }
  if (layout) {
    for (const auto& [a, b] : layout->feature_edges) {
      const auto h = mesh.find_halfedge(mesh.vertex_handle(a), mesh.vertex_handle(b));
      if (h.is_valid() && !mesh.is_boundary(mesh.edge_handle(h)))
        sharp[mesh.edge_handle(h).idx()] = 1;
    }
  }
  return sharp;
}

FieldConstraints collect_constraints(const TriMesh& mesh, const GeometryCache& g,
                                     const Layout* layout, const ConstraintOptions& opt,
                                     const Curvature* curvature) {
  const int nf = g.n_faces;
  std::vector<int> kind(nf, -1);
  std::vector<Vec3> dir(nf);
  auto edge_dir = [&](int e) {
    const auto [a, b] = g.edge_vertices[e];
    Vec3 d = mesh.point(mesh.vertex_handle(b)) - mesh.point(mesh.vertex_handle(a));
    return d.normalize();
  };
  if (opt.curvature && curvature) {
    for (int f = 0; f < nf; ++f)
      if (curvature->reliable[f])
        kind[f] = static_cast<int>(ConstraintKind::Curvature), dir[f] = curvature->dir_max[f];
  }
  if (opt.features) {
    const auto sharp = sharp_edges(mesh, g, opt.sharp_angle_deg, layout);
    for (int e = 0; e < g.n_edges; ++e) {
      if (!sharp[e]) continue;
      for (int f : {g.edge_face_i[e], g.edge_face_j[e]}) {
        if (f < 0 || kind[f] >= static_cast<int>(ConstraintKind::Feature)) continue;
        kind[f] = static_cast<int>(ConstraintKind::Feature);
        dir[f] = edge_dir(e);
      }
    }
  }
  if (opt.boundary) {
    // Only boundary edges that arcs run along: a boundary crossed by dangling arcs (trimmed
    // patches) is free, and aligning the field to it would force singularities the layout
    // does not have (a disk's boundary turns by 2π).
    std::vector<char> on_arc(g.n_edges, 0);
    if (layout) {
      for (const auto& arc : layout->arcs)
        for (size_t k = 0; k + 1 < arc.path.size(); ++k) {
          const auto h = mesh.find_halfedge(mesh.vertex_handle(arc.path[k]),
                                            mesh.vertex_handle(arc.path[k + 1]));
          if (h.is_valid()) on_arc[mesh.edge_handle(h).idx()] = 1;
        }
    }
    for (int e = 0; e < g.n_edges; ++e) {
      if (layout && !on_arc[e]) continue;
      const int f = g.edge_face_i[e] >= 0 && g.edge_face_j[e] < 0   ? g.edge_face_i[e]
                    : g.edge_face_j[e] >= 0 && g.edge_face_i[e] < 0 ? g.edge_face_j[e]
                                                                    : -1;
      if (f < 0) continue;
      kind[f] = static_cast<int>(ConstraintKind::Boundary);
      dir[f] = edge_dir(e);
    }
  }
  FieldConstraints c;
  for (int f = 0; f < nf; ++f) {
    if (kind[f] < 0) continue;
    // Project onto the face plane (feature edges lie in it already).
    Vec3 d = dir[f] - (dir[f] | g.face_normal[f]) * g.face_normal[f];
    if (d.norm() < 1e-12) continue;
    c.face.push_back(f);
    c.direction.push_back(d.normalize());
    c.kind.push_back(static_cast<ConstraintKind>(kind[f]));
  }
  return c;
}

}  // namespace qs
