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

namespace {

// Contribution β_e·(|e|/2)·ê êᵀ of edge e to the tensors of its end vertices; false when it is
// zero (flat or degenerate edge).
bool edge_tensor(const TriMesh& mesh, const GeometryCache& g, int e, Eigen::Matrix3d& m) {
  const double beta = signed_dihedral(mesh, g, e);
  if (beta == 0.0) return false;
  const auto [a, b] = g.edge_vertices[e];
  const Vec3 d = mesh.point(mesh.vertex_handle(b)) - mesh.point(mesh.vertex_handle(a));
  const double len = d.norm();
  if (len == 0) return false;
  const Eigen::Vector3d u(d[0] / len, d[1] / len, d[2] / len);
  m = beta * 0.5 * len * (u * u.transpose());
  return true;
}

// One smoothing step at vertex v: the mean over v and its neighbours of the previous level.
void smooth_vertex(const TriMesh& mesh, OpenMesh::VertexHandle v,
                   const std::vector<Eigen::Matrix3d>& t_in, const std::vector<double>& a_in,
                   Eigen::Matrix3d& t_out, double& a_out) {
  Eigen::Matrix3d t = t_in[v.idx()];
  double a = a_in[v.idx()];
  int count = 1;
  for (auto w : mesh.vv_range(v)) {
    t += t_in[w.idx()];
    a += a_in[w.idx()];
    ++count;
  }
  t_out = t / count;
  a_out = a / count;
}

// Principal curvatures and direction of face f from the smoothed vertex tensors; returns
// max(|κ1|, |κ2|).
double face_curvature(const GeometryCache& g, int f, const std::vector<Eigen::Matrix3d>& smooth_t,
                      const std::vector<double>& smooth_a, Curvature& c) {
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
  return std::max(std::abs(c.k_max[f]), std::abs(c.k_min[f]));
}

// The reliable set from the per-face curvatures (global 95th percentile, small regions
// dropped).
void classify_reliable(const TriMesh& mesh, const CurvatureOptions& opt,
                       const std::vector<double>& magnitude, Curvature& c) {
  const int nf = static_cast<int>(magnitude.size());
  c.reliable.assign(nf, 0);
  c.reliable_faces = 0;
  if (nf == 0) return;
  std::vector<double> sorted = magnitude;
  const size_t q = static_cast<size_t>(0.95 * (nf - 1));
  std::nth_element(sorted.begin(), sorted.begin() + q, sorted.end());
  const double s95 = sorted[q];
  if (s95 <= 0) return;
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
}

}  // namespace

Curvature compute_curvature(const TriMesh& mesh, const GeometryCache& g,
                            const CurvatureOptions& opt, CurvatureCache* cache) {
  const int nv = g.n_vertices, nf = g.n_faces;
  const int levels = std::max(1, opt.rings);
  // Per-vertex tensor: Σ over incident edges of β_e·(|e|/2)·ê êᵀ, with its area A_v/3 share.
  std::vector<std::vector<Eigen::Matrix3d>> tensor(
      1, std::vector<Eigen::Matrix3d>(nv, Eigen::Matrix3d::Zero()));
  std::vector<std::vector<double>> area(1, std::vector<double>(nv, 0.0));
  Eigen::Matrix3d m;
  for (int e = 0; e < g.n_edges; ++e) {
    if (!edge_tensor(mesh, g, e, m)) continue;
    const auto [a, b] = g.edge_vertices[e];
    tensor[0][a] += m;
    tensor[0][b] += m;
  }
  for (int f = 0; f < nf; ++f)
    for (int v : g.face_vertices[f]) area[0][v] += g.face_area[f] / 3.0;

  // Smooth over rings: vertex neighbourhoods grown by BFS up to `rings` edges.
  for (int r = 1; r < levels; ++r) {
    tensor.emplace_back(nv);
    area.emplace_back(nv);
    for (auto v : mesh.vertices())
      smooth_vertex(mesh, v, tensor[r - 1], area[r - 1], tensor[r][v.idx()], area[r][v.idx()]);
  }

  Curvature c;
  c.k_max.resize(nf);
  c.k_min.resize(nf);
  c.dir_max.resize(nf);
  std::vector<double> magnitude(nf);
  for (int f = 0; f < nf; ++f) magnitude[f] = face_curvature(g, f, tensor.back(), area.back(), c);
  classify_reliable(mesh, opt, magnitude, c);
  if (cache) {
    cache->points.resize(nv);
    for (auto v : mesh.vertices()) cache->points[v.idx()] = mesh.point(v);
    cache->tensor = std::move(tensor);
    cache->area = std::move(area);
    cache->magnitude = std::move(magnitude);
    cache->curvature = c;
    cache->options = opt;
  }
  return c;
}

Curvature update_curvature(const TriMesh& mesh, const GeometryCache& g, const CurvatureOptions& opt,
                           CurvatureCache& cache) {
  const int nv = g.n_vertices, nf = g.n_faces;
  const int levels = std::max(1, opt.rings);
  if (static_cast<int>(cache.points.size()) != nv ||
      static_cast<int>(cache.magnitude.size()) != nf ||
      static_cast<int>(cache.tensor.size()) != levels || cache.options != opt)
    return compute_curvature(mesh, g, opt, &cache);
  // Vertices whose tensor or area can change: the vertices of the faces around moved ones.
  std::vector<char> moved(nv, 0), in_set(nv, 0);
  bool any = false;
  for (auto v : mesh.vertices())
    if (mesh.point(v) != cache.points[v.idx()]) moved[v.idx()] = 1, any = true;
  if (!any) return cache.curvature;
  std::vector<int> set;
  for (int f = 0; f < nf; ++f) {
    const auto& fv = g.face_vertices[f];
    if (!moved[fv[0]] && !moved[fv[1]] && !moved[fv[2]]) continue;
    for (int v : fv)
      if (!in_set[v]) in_set[v] = 1, set.push_back(v);
  }
  // Level 0, summed in the same (edge, face) order as compute_curvature: bit-identical.
  for (int v : set) cache.tensor[0][v].setZero(), cache.area[0][v] = 0.0;
  Eigen::Matrix3d m;
  for (int e = 0; e < g.n_edges; ++e) {
    const auto [a, b] = g.edge_vertices[e];
    if (!in_set[a] && !in_set[b]) continue;
    if (!edge_tensor(mesh, g, e, m)) continue;
    if (in_set[a]) cache.tensor[0][a] += m;
    if (in_set[b]) cache.tensor[0][b] += m;
  }
  for (int f = 0; f < nf; ++f)
    for (int v : g.face_vertices[f])
      if (in_set[v]) cache.area[0][v] += g.face_area[f] / 3.0;
  // Each smoothing level reaches one ring further.
  for (int r = 1; r < levels; ++r) {
    const size_t before = set.size();
    for (size_t k = 0; k < before; ++k)
      for (auto w : mesh.vv_range(mesh.vertex_handle(set[k])))
        if (!in_set[w.idx()]) in_set[w.idx()] = 1, set.push_back(w.idx());
    for (int v : set)
      smooth_vertex(mesh, mesh.vertex_handle(v), cache.tensor[r - 1], cache.area[r - 1],
                    cache.tensor[r][v], cache.area[r][v]);
  }
  Curvature& c = cache.curvature;
  for (int f = 0; f < nf; ++f) {
    const auto& fv = g.face_vertices[f];
    if (in_set[fv[0]] || in_set[fv[1]] || in_set[fv[2]])
      cache.magnitude[f] = face_curvature(g, f, cache.tensor.back(), cache.area.back(), c);
  }
  classify_reliable(mesh, opt, cache.magnitude, c);
  for (auto v : mesh.vertices())
    if (moved[v.idx()]) cache.points[v.idx()] = mesh.point(v);
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
    const std::vector<char> on_arc =
        layout ? arc_edge_mask(mesh, *layout) : std::vector<char>(g.n_edges, 0);
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
