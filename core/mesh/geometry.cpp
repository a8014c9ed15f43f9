#include "core/mesh/geometry.h"

#include <algorithm>
#include <cmath>

namespace qs {

std::array<std::array<double, 2>, 3> face_corners_2d(const TriMesh& mesh, const GeometryCache& g,
                                                     int f) {
  const auto& fv = g.face_vertices[f];
  const Vec3& r = g.face_frame[f];
  const Vec3 s = g.face_normal[f] % r;
  const Vec3 x0 = mesh.point(mesh.vertex_handle(fv[0]));
  std::array<std::array<double, 2>, 3> p{};
  for (int k = 0; k < 3; ++k) {
    const Vec3 d = mesh.point(mesh.vertex_handle(fv[k])) - x0;
    p[k] = {d | r, d | s};
  }
  return p;
}

double wrap_angle(double a) {
  a = std::remainder(a, 2 * M_PI);  // [−π, π]
  if (a <= -M_PI) a += 2 * M_PI;
  return a;
}

double GeometryCache::angle_in_face(int f, const Vec3& v) const {
  const Vec3& r = face_frame[f];
  const Vec3 jr = face_normal[f] % r;
  return std::atan2(v | jr, v | r);
}

Vec3 GeometryCache::direction_in_face(int f, double phi) const {
  const Vec3& r = face_frame[f];
  return std::cos(phi) * r + std::sin(phi) * (face_normal[f] % r);
}

namespace {

// Normal, area, frame and corner angles of face f.
void compute_face(const TriMesh& mesh, GeometryCache& g, int f) {
  const auto& fv = g.face_vertices[f];
  const Vec3 p[3] = {mesh.point(mesh.vertex_handle(fv[0])), mesh.point(mesh.vertex_handle(fv[1])),
                     mesh.point(mesh.vertex_handle(fv[2]))};
  Vec3 n = (p[1] - p[0]) % (p[2] - p[0]);
  const double len = n.norm();
  g.face_area[f] = 0.5 * len;
  g.face_normal[f] = len > 0 ? n / len : Vec3(0, 0, 1);
  Vec3 r = p[1] - p[0];
  const double rl = r.norm();
  r = rl > 0 ? r / rl : Vec3(1, 0, 0);
  const double off = g.frame_offset[f];
  g.face_frame[f] = off == 0.0 ? r : std::cos(off) * r + std::sin(off) * (g.face_normal[f] % r);
  for (int k = 0; k < 3; ++k) {
    const Vec3 a = p[(k + 1) % 3] - p[k], b = p[(k + 2) % 3] - p[k];
    g.corner_angle[3 * f + k] = std::atan2((a % b).norm(), a | b);
  }
  // Hat-function gradients in the frame just set: ∇φ_k is the opposite edge e_k turned by 90°
  // (−e_y, e_x), divided by twice the area.
  const auto c = face_corners_2d(mesh, g, f);
  const double e1x = c[1][0] - c[0][0], e1y = c[1][1] - c[0][1];
  const double e2x = c[2][0] - c[0][0], e2y = c[2][1] - c[0][1];
  const double a2 = e1x * e2y - e1y * e2x;
  std::array<double, 7>& grad = g.face_gradient[f];
  for (int k = 0; k < 3; ++k) {
    const auto& from = c[(k + 1) % 3];
    const auto& to = c[(k + 2) % 3];
    grad[2 * k] = -(to[1] - from[1]) / a2;
    grad[2 * k + 1] = (to[0] - from[0]) / a2;
  }
  grad[6] = 0.5 * a2;
}

// Length and κ of edge e (κ continued from \p old_kappa when given).
void compute_edge(const TriMesh& mesh, GeometryCache& g, int e, const double* old_kappa) {
  const auto [a, b] = g.edge_vertices[e];
  const Vec3 t = mesh.point(mesh.vertex_handle(b)) - mesh.point(mesh.vertex_handle(a));
  g.edge_length[e] = t.norm();
  // κ_ij = α_i − α_j with α_f the angle from the edge direction t = x_b − x_a to r_f.
  const int i = g.edge_face_i[e], j = g.edge_face_j[e];
  if (i < 0 || j < 0) {
    g.kappa[e] = 0.0;
    return;
  }
  const double alpha_i = -g.angle_in_face(i, t);
  const double alpha_j = -g.angle_in_face(j, t);
  const double k = wrap_angle(alpha_i - alpha_j);
  g.kappa[e] = old_kappa ? *old_kappa + wrap_angle(k - *old_kappa) : k;
}

// Angle defect of v from its faces' corner angles, summed in increasing face order (as the
// full computation accumulates them).
void compute_defect(GeometryCache& g, int v) {
  double sum = 0.0;
  for (int i = g.vertex_face_offset[v]; i < g.vertex_face_offset[v + 1]; ++i) {
    const int f = g.vertex_faces[i];
    const auto& fv = g.face_vertices[f];
    for (int k = 0; k < 3; ++k)
      if (fv[k] == v) sum += g.corner_angle[3 * f + k];
  }
  g.angle_defect[v] = (g.vertex_on_boundary[v] ? M_PI : 2 * M_PI) - sum;
}

// Bounding box diagonal and mean edge length from positions and edge_length.
void compute_totals(const TriMesh& mesh, GeometryCache& g) {
  Vec3 lo(1e300, 1e300, 1e300), hi(-1e300, -1e300, -1e300);
  for (auto v : mesh.vertices()) {
    lo.minimize(mesh.point(v));
    hi.maximize(mesh.point(v));
  }
  g.bbox_diagonal = g.n_vertices ? (hi - lo).norm() : 0.0;
  double length_sum = 0;
  for (double l : g.edge_length) length_sum += l;
  g.mean_edge_length = g.n_edges ? length_sum / g.n_edges : 0.0;
}

// Transport residual of interior vertex v: Σ σ·κ over its edges (σ = +1 when the loop around
// v, counter-clockwise, crosses the edge from face i to face j, i.e. v is the edge's second
// vertex) minus the angle defect. A multiple of 2π; constant while κ is continued correctly.
double transport_residual(const GeometryCache& g, int v) {
  double h = 0;
  for (int i = g.vertex_face_offset[v]; i < g.vertex_face_offset[v + 1]; ++i) {
    const int f = g.vertex_faces[i];
    for (int e : g.face_edges[f]) {
      if (g.edge_face_i[e] != f) continue;  // each edge once (from its face i)
      const auto& ev = g.edge_vertices[e];
      if (ev[1] == v)
        h += g.kappa[e];
      else if (ev[0] == v)
        h -= g.kappa[e];
    }
  }
  return h - g.angle_defect[v];
}

// After κ was continued on some edges (old values \p old_kappa, per edge, NaN where κ was not
// recomputed): a single update in which an edge's frames turn by more than π against each
// other (a vertex relocated far within its 1-ring, next to a short edge) makes the continuation
// take the wrong branch, κ off by 2π, and with the period jumps unchanged two vertices gain
// index ±4 (spurious singularities, fold-overs: seen on the bundled example after a hop).
// Each interior vertex's transport residual (\p residual_before, for \p vertices) must stay
// the same; an edge between two vertices whose residuals moved by +2π and −2π is turned back
// by 2π (the one whose κ moved most first).
void restore_transport(GeometryCache& g, const std::vector<int>& vertices,
                       const std::vector<double>& residual_before,
                       const std::vector<double>& old_kappa) {
  std::vector<int> off;  // vertices whose residual moved
  std::vector<int> turns(g.n_vertices, 0);
  for (size_t k = 0; k < vertices.size(); ++k) {
    const int v = vertices[k];
    const int m =
        static_cast<int>(std::lround((transport_residual(g, v) - residual_before[k]) / (2 * M_PI)));
    if (m != 0) turns[v] = m, off.push_back(v);
  }
  for (bool progress = !off.empty(); progress;) {
    progress = false;
    for (int v : off) {
      if (turns[v] == 0) continue;
      const int sign = turns[v] > 0 ? 1 : -1;
      // Candidates: edges of v to a vertex whose residual moved the other way.
      int best = -1;
      double best_change = -1;
      for (int i = g.vertex_face_offset[v]; i < g.vertex_face_offset[v + 1]; ++i) {
        const int f = g.vertex_faces[i];
        for (int e : g.face_edges[f]) {
          if (g.edge_face_i[e] != f || std::isnan(old_kappa[e])) continue;
          const auto& ev = g.edge_vertices[e];
          if (ev[0] != v && ev[1] != v) continue;
          const int u = ev[0] == v ? ev[1] : ev[0];
          if (turns[u] * sign >= 0) continue;
          const double change = std::abs(g.kappa[e] - old_kappa[e]);
          if (change > best_change) best_change = change, best = e;
        }
      }
      if (best < 0) continue;
      const auto& ev = g.edge_vertices[best];
      const int u = ev[0] == v ? ev[1] : ev[0];
      const double s = ev[1] == v ? 1.0 : -1.0;  // σ of v on this edge
      g.kappa[best] -= 2 * M_PI * s * sign;      // v's residual −2π·sign, u's +2π·sign
      turns[v] -= sign;
      turns[u] += sign;
      progress = true;
    }
  }
}

// The interior vertices of \p faces and their transport residuals (restore_transport).
void residuals_of(const GeometryCache& g, const std::vector<int>& faces, std::vector<int>& vertices,
                  std::vector<double>& residuals) {
  std::vector<char> seen(g.n_vertices, 0);
  for (int f : faces)
    for (int v : g.face_vertices[f])
      if (!seen[v] && !g.vertex_on_boundary[v]) {
        seen[v] = 1;
        vertices.push_back(v);
        residuals.push_back(transport_residual(g, v));
      }
}

void compute_geometry(const TriMesh& mesh, GeometryCache& g, bool continue_kappa) {
  const int nf = g.n_faces;
  std::vector<int> residual_vertices;
  std::vector<double> residuals;
  if (continue_kappa && static_cast<int>(g.kappa.size()) == g.n_edges &&
      static_cast<int>(g.angle_defect.size()) == g.n_vertices) {
    std::vector<int> all(nf);
    for (int f = 0; f < nf; ++f) all[f] = f;
    residuals_of(g, all, residual_vertices, residuals);
  }
  g.face_normal.resize(nf);
  g.face_frame.resize(nf);
  g.face_area.resize(nf);
  g.face_gradient.resize(nf);
  g.corner_angle.resize(3 * nf);
  g.angle_defect.assign(g.n_vertices, 0.0);
  std::vector<double> angle_sum(g.n_vertices, 0.0);
  for (int f = 0; f < nf; ++f) {
    compute_face(mesh, g, f);
    for (int k = 0; k < 3; ++k) angle_sum[g.face_vertices[f][k]] += g.corner_angle[3 * f + k];
  }
  for (int v = 0; v < g.n_vertices; ++v)
    g.angle_defect[v] = (g.vertex_on_boundary[v] ? M_PI : 2 * M_PI) - angle_sum[v];
  std::vector<double> old;
  if (continue_kappa) old = g.kappa;
  g.kappa.assign(g.n_edges, 0.0);
  g.edge_length.assign(g.n_edges, 0.0);
  for (int e = 0; e < g.n_edges; ++e) compute_edge(mesh, g, e, continue_kappa ? &old[e] : nullptr);
  if (continue_kappa && !residual_vertices.empty())
    restore_transport(g, residual_vertices, residuals, old);
  compute_totals(mesh, g);
  g.positions.resize(g.n_vertices);
  for (auto v : mesh.vertices()) g.positions[v.idx()] = mesh.point(v);
}

}  // namespace

GeometryCache build_geometry(const TriMesh& mesh) {
  GeometryCache g;
  g.n_vertices = static_cast<int>(mesh.n_vertices());
  g.n_faces = static_cast<int>(mesh.n_faces());
  g.n_edges = static_cast<int>(mesh.n_edges());
  g.face_vertices.resize(g.n_faces);
  for (auto f : mesh.faces()) {
    int k = 0;
    for (auto v : mesh.fv_range(f)) g.face_vertices[f.idx()][k++] = v.idx();
  }
  g.edge_face_i.assign(g.n_edges, -1);
  g.edge_face_j.assign(g.n_edges, -1);
  g.edge_vertices.resize(g.n_edges);
  for (auto e : mesh.edges()) {
    auto h = mesh.halfedge_handle(e, 0);
    if (mesh.from_vertex_handle(h).idx() > mesh.to_vertex_handle(h).idx())
      h = mesh.opposite_halfedge_handle(h);
    g.edge_vertices[e.idx()] = {mesh.from_vertex_handle(h).idx(), mesh.to_vertex_handle(h).idx()};
    const auto fi = mesh.face_handle(h);
    const auto fj = mesh.face_handle(mesh.opposite_halfedge_handle(h));
    g.edge_face_i[e.idx()] = fi.is_valid() ? fi.idx() : -1;
    g.edge_face_j[e.idx()] = fj.is_valid() ? fj.idx() : -1;
  }
  g.face_edges.resize(g.n_faces);
  for (auto f : mesh.faces()) {
    int k = 0;
    for (auto e : mesh.fe_range(f)) g.face_edges[f.idx()][k++] = e.idx();
  }
  g.vertex_face_offset.assign(g.n_vertices + 1, 0);
  for (const auto& fv : g.face_vertices)
    for (int v : fv) ++g.vertex_face_offset[v + 1];
  for (int v = 0; v < g.n_vertices; ++v) g.vertex_face_offset[v + 1] += g.vertex_face_offset[v];
  g.vertex_faces.resize(g.vertex_face_offset[g.n_vertices]);
  {
    std::vector<int> fill(g.vertex_face_offset.begin(), g.vertex_face_offset.end() - 1);
    for (int f = 0; f < g.n_faces; ++f)
      for (int v : g.face_vertices[f]) g.vertex_faces[fill[v]++] = f;
  }
  g.frame_offset.assign(g.n_faces, 0.0);
  g.vertex_on_boundary.assign(g.n_vertices, 0);
  for (auto v : mesh.vertices()) g.vertex_on_boundary[v.idx()] = mesh.is_boundary(v);
  compute_geometry(mesh, g, false);
  return g;
}

void update_geometry(const TriMesh& mesh, GeometryCache& g) {
  const bool incremental = static_cast<int>(g.positions.size()) == g.n_vertices &&
                           static_cast<int>(mesh.n_vertices()) == g.n_vertices &&
                           static_cast<int>(g.face_edges.size()) == g.n_faces &&
                           static_cast<int>(g.vertex_face_offset.size()) == g.n_vertices + 1 &&
                           static_cast<int>(g.edge_length.size()) == g.n_edges;
  std::vector<int> moved;
  if (incremental) {
    for (auto v : mesh.vertices())
      if (mesh.point(v) != g.positions[v.idx()]) moved.push_back(v.idx());
    if (moved.empty()) return;  // the full computation would reproduce every value
  }
  if (!incremental || moved.size() * 8 > static_cast<size_t>(g.n_vertices)) {
    compute_geometry(mesh, g, true);
    return;
  }
  std::vector<int> faces, vertices, edges;
  std::vector<char> seen_face(g.n_faces, 0);
  for (int v : moved)
    for (int i = g.vertex_face_offset[v]; i < g.vertex_face_offset[v + 1]; ++i) {
      const int f = g.vertex_faces[i];
      if (!seen_face[f]) seen_face[f] = 1, faces.push_back(f);
    }
  std::vector<int> residual_vertices;
  std::vector<double> residuals;
  residuals_of(g, faces, residual_vertices, residuals);
  for (int f : faces) compute_face(mesh, g, f);
  std::vector<char> seen_vertex(g.n_vertices, 0), seen_edge(g.n_edges, 0);
  std::vector<double> old_kappa(g.n_edges, std::nan(""));
  for (int f : faces) {
    for (int v : g.face_vertices[f])
      if (!seen_vertex[v]) seen_vertex[v] = 1, compute_defect(g, v);
    for (int e : g.face_edges[f])
      if (!seen_edge[e])
        seen_edge[e] = 1, old_kappa[e] = g.kappa[e], compute_edge(mesh, g, e, &g.kappa[e]);
  }
  restore_transport(g, residual_vertices, residuals, old_kappa);
  compute_totals(mesh, g);
  for (int v : moved) g.positions[v] = mesh.point(mesh.vertex_handle(v));
}

void set_frame_offsets(const TriMesh& mesh, GeometryCache& geometry, std::vector<double> offsets) {
  geometry.frame_offset = std::move(offsets);
  compute_geometry(mesh, geometry, false);
}

}  // namespace qs
