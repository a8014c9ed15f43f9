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

void compute_geometry(const TriMesh& mesh, GeometryCache& g, bool continue_kappa) {
  const int nf = g.n_faces;
  g.face_normal.resize(nf);
  g.face_frame.resize(nf);
  g.face_area.resize(nf);
  g.corner_angle.resize(3 * nf);
  g.angle_defect.assign(g.n_vertices, 0.0);
  Vec3 lo(1e300, 1e300, 1e300), hi(-1e300, -1e300, -1e300);
  for (auto v : mesh.vertices()) {
    lo.minimize(mesh.point(v));
    hi.maximize(mesh.point(v));
  }
  g.bbox_diagonal = g.n_vertices ? (hi - lo).norm() : 0.0;
  std::vector<double> angle_sum(g.n_vertices, 0.0);
  for (int f = 0; f < nf; ++f) {
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
      const double ang = std::atan2((a % b).norm(), a | b);
      g.corner_angle[3 * f + k] = ang;
      angle_sum[fv[k]] += ang;
    }
  }
  for (int v = 0; v < g.n_vertices; ++v)
    g.angle_defect[v] = (g.vertex_on_boundary[v] ? M_PI : 2 * M_PI) - angle_sum[v];

  // κ_ij = α_i − α_j with α_f the angle from the edge direction t = x_b − x_a to r_f.
  std::vector<double> old;
  if (continue_kappa) old = g.kappa;
  g.kappa.assign(g.n_edges, 0.0);
  double length_sum = 0;
  for (int e = 0; e < g.n_edges; ++e) {
    const auto [a, b] = g.edge_vertices[e];
    const Vec3 t = mesh.point(mesh.vertex_handle(b)) - mesh.point(mesh.vertex_handle(a));
    length_sum += t.norm();
    const int i = g.edge_face_i[e], j = g.edge_face_j[e];
    if (i < 0 || j < 0) continue;
    const double alpha_i = -g.angle_in_face(i, t);
    const double alpha_j = -g.angle_in_face(j, t);
    const double k = wrap_angle(alpha_i - alpha_j);
    g.kappa[e] = continue_kappa ? old[e] + wrap_angle(k - old[e]) : k;
  }
  g.mean_edge_length = g.n_edges ? length_sum / g.n_edges : 0.0;
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
  g.frame_offset.assign(g.n_faces, 0.0);
  g.vertex_on_boundary.assign(g.n_vertices, 0);
  for (auto v : mesh.vertices()) g.vertex_on_boundary[v.idx()] = mesh.is_boundary(v);
  compute_geometry(mesh, g, false);
  return g;
}

void update_geometry(const TriMesh& mesh, GeometryCache& geometry) {
  compute_geometry(mesh, geometry, true);
}

void set_frame_offsets(const TriMesh& mesh, GeometryCache& geometry, std::vector<double> offsets) {
  geometry.frame_offset = std::move(offsets);
  compute_geometry(mesh, geometry, false);
}

}  // namespace qs
