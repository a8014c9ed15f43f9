#include "core/nodeopt/geodesic.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

namespace qs {

namespace {

struct FaceGeom {
  int v[3];
  Vec3 p[3];
  Vec3 n;
  double a2 = 0;  // twice the area
};

FaceGeom face_geom(const TriMesh& mesh, int f) {
  FaceGeom g;
  int k = 0;
  for (auto vh : mesh.fv_range(mesh.face_handle(f))) {
    g.v[k] = vh.idx();
    g.p[k] = mesh.point(vh);
    ++k;
  }
  const Vec3 c = (g.p[1] - g.p[0]) % (g.p[2] - g.p[0]);
  g.a2 = c.norm();
  g.n = g.a2 > 0 ? c / g.a2 : Vec3(0, 0, 1);
  return g;
}

int corner_in(const FaceGeom& g, int v) {
  return g.v[0] == v ? 0 : (g.v[1] == v ? 1 : (g.v[2] == v ? 2 : -1));
}

Vec3 in_plane(const Vec3& d, const Vec3& n) {
  return d - (d | n) * n;
}

// Picks the face around vertex v whose corner wedge contains the direction d (projected into
// each face); the direction comes back projected into that face (unit), clamped into the wedge
// when no wedge contains it.
int pick_wedge(const TriMesh& mesh, int v, const Vec3& d, Vec3& out_dir) {
  int best = -1;
  double best_score = -std::numeric_limits<double>::infinity();
  for (auto fh : mesh.vf_range(mesh.vertex_handle(v))) {
    const FaceGeom g = face_geom(mesh, fh.idx());
    const int c = corner_in(g, v);
    Vec3 dp = in_plane(d, g.n);
    const double len = dp.norm();
    if (len <= 0) continue;
    dp /= len;
    const Vec3 a = (g.p[(c + 1) % 3] - g.p[c]).normalized();
    const Vec3 b = (g.p[(c + 2) % 3] - g.p[c]).normalized();
    const double sa = (a % dp) | g.n, sb = (dp % b) | g.n;
    double score;
    Vec3 dir = dp;
    if (sa >= 0 && sb >= 0) {
      score = 2.0 + (dp | (a + b).normalized());
    } else {
      score = dp | (a + b).normalized();
      dir = (dp | a) > (dp | b) ? a : b;  // clamp to the nearer wedge edge
      dir = (dir + 1e-6 * (a + b)).normalized();
    }
    if (score > best_score) {
      best_score = score;
      best = fh.idx();
      out_dir = dir;
    }
  }
  return best;
}

// Leaves interior vertex v after arriving in face f_in with direction d (pointing at v): the
// outgoing direction has the same angle Θ/2 to the incoming one on both sides (Θ = angle sum).
int leave_vertex(const TriMesh& mesh, int v, int f_in, const Vec3& d, Vec3& out_dir) {
  struct Wedge {
    int face;
    Vec3 a, n;  // unit first edge (ccw start) and face normal
    double angle;
  };
  std::vector<Wedge> wedges;
  const auto vh = mesh.vertex_handle(v);
  auto h0 = mesh.halfedge_handle(vh);
  auto h = h0;
  do {
    const FaceGeom g = face_geom(mesh, mesh.face_handle(h).idx());
    const int c = corner_in(g, v);
    const Vec3 a = (g.p[(c + 1) % 3] - g.p[c]).normalized();
    const Vec3 b = (g.p[(c + 2) % 3] - g.p[c]).normalized();
    wedges.push_back({mesh.face_handle(h).idx(), a, g.n, std::atan2((a % b).norm(), a | b)});
    h = mesh.opposite_halfedge_handle(mesh.prev_halfedge_handle(h));
  } while (h != h0 && wedges.size() < 1000);
  double total = 0, phi_in = -1;
  for (const auto& w : wedges) {
    if (w.face == f_in) {
      const Vec3 r = -d;
      phi_in = total + std::atan2((w.a % r) | w.n, w.a | r);
    }
    total += w.angle;
  }
  if (phi_in < 0 && phi_in > -1e-9) phi_in = 0;
  if (phi_in < 0 || total <= 0) return -1;
  double phi = std::fmod(phi_in + 0.5 * total, total);
  for (const auto& w : wedges) {
    if (phi <= w.angle || &w == &wedges.back()) {
      phi = std::min(phi, w.angle);
      out_dir = std::cos(phi) * w.a + std::sin(phi) * (w.n % w.a);
      return w.face;
    }
    phi -= w.angle;
  }
  return -1;
}

}  // namespace

Vec3 surface_position(const TriMesh& mesh, const SurfacePoint& p) {
  const FaceGeom g = face_geom(mesh, p.face);
  return p.bary[0] * g.p[0] + p.bary[1] * g.p[1] + p.bary[2] * g.p[2];
}

SurfacePoint vertex_surface_point(const TriMesh& mesh, int v) {
  SurfacePoint s;
  for (auto fh : mesh.vf_range(mesh.vertex_handle(v))) {
    const FaceGeom g = face_geom(mesh, fh.idx());
    s.face = fh.idx();
    s.bary = {0, 0, 0};
    s.bary[corner_in(g, v)] = 1.0;
    break;
  }
  return s;
}

GeodesicTrace trace_straightest_geodesic(const TriMesh& mesh, const SurfacePoint& start,
                                         const Vec3& direction, double length,
                                         const std::function<bool(int)>& blocked_face) {
  constexpr double kZero = 1e-10;
  GeodesicTrace out;
  int f = start.face;
  double b[3] = {start.bary[0], start.bary[1], start.bary[2]};
  Vec3 d = direction;
  auto finish = [&](int face, const double* bary) {
    out.end.face = face;
    out.end.bary = {std::max(0.0, bary[0]), std::max(0.0, bary[1]), std::max(0.0, bary[2])};
    const double s = out.end.bary[0] + out.end.bary[1] + out.end.bary[2];
    for (double& x : out.end.bary) x /= s;
    out.end_position = surface_position(mesh, out.end);
    return out;
  };
  if (d.norm() <= 0 || length <= 0) return finish(f, b);

  // Enters the vertex at corner c of the current face: picks the outgoing wedge.
  auto through_vertex = [&](int vertex) -> bool {
    if (mesh.is_boundary(mesh.vertex_handle(vertex))) {
      out.hit_boundary = true;
      return false;
    }
    Vec3 dir;
    int g = -1;
    if (!out.faces.empty()) g = leave_vertex(mesh, vertex, f, d, dir);
    if (g < 0) g = pick_wedge(mesh, vertex, d, dir);
    if (g < 0) return false;
    if (g != f && blocked_face && blocked_face(g)) {
      out.truncated = true;
      return false;
    }
    const FaceGeom fg = face_geom(mesh, g);
    f = g;
    b[0] = b[1] = b[2] = 0;
    b[corner_in(fg, vertex)] = 1;
    d = dir;
    return true;
  };

  {
    const int c = static_cast<int>(std::max_element(b, b + 3) - b);
    if (b[c] > 1 - kZero) {
      const FaceGeom g = face_geom(mesh, f);
      if (!through_vertex(g.v[c])) return finish(f, b);
    }
  }
  out.faces.push_back(f);
  double remaining = length;
  for (int iter = 0; iter < 100000 && remaining > 0; ++iter) {
    const FaceGeom g = face_geom(mesh, f);
    d = in_plane(d, g.n);
    if (d.norm() <= 0 || g.a2 <= 0) break;
    d.normalize();
    double db[3];
    for (int i = 0; i < 3; ++i) {
      const Vec3 e = g.p[(i + 2) % 3] - g.p[(i + 1) % 3];
      db[i] = ((g.n % e) | d) / g.a2;
      if (b[i] <= kZero && db[i] < 0 && db[i] > -1e-9) db[i] = 0;  // grazing an edge
    }
    int exit = -1;
    double t_exit = std::numeric_limits<double>::infinity();
    for (int i = 0; i < 3; ++i) {
      if (db[i] >= 0) continue;
      const double t = std::max(0.0, b[i]) / -db[i];
      if (t < t_exit) {
        t_exit = t;
        exit = i;
      }
    }
    if (exit < 0 || t_exit >= remaining) {
      for (int i = 0; i < 3; ++i) b[i] += remaining * db[i];
      out.length += remaining;
      return finish(f, b);
    }
    for (int i = 0; i < 3; ++i) b[i] += t_exit * db[i];
    b[exit] = 0;
    remaining -= t_exit;
    out.length += t_exit;
    // Through a vertex when a second barycentric vanished too.
    int at_vertex = -1;
    for (int i = 0; i < 3; ++i)
      if (i != exit && b[i] <= 1e-9) at_vertex = 3 - i - exit;
    if (at_vertex >= 0) {
      b[0] = b[1] = b[2] = 0;
      b[at_vertex] = 1;
      const int from = f;
      if (!through_vertex(g.v[at_vertex])) return finish(f, b);
      if (f != from) out.faces.push_back(f);
      continue;
    }
    const int va = g.v[(exit + 1) % 3], vb = g.v[(exit + 2) % 3];
    const auto h = mesh.find_halfedge(mesh.vertex_handle(va), mesh.vertex_handle(vb));
    const auto oh = mesh.opposite_halfedge_handle(h);
    if (mesh.is_boundary(oh)) {
      out.hit_boundary = true;
      return finish(f, b);
    }
    const int next = mesh.face_handle(oh).idx();
    if (blocked_face && blocked_face(next)) {
      out.truncated = true;
      return finish(f, b);
    }
    const FaceGeom ng = face_geom(mesh, next);
    const Vec3 e = (g.p[(exit + 2) % 3] - g.p[(exit + 1) % 3]).normalized();
    const double along = d | e, across = d | (g.n % e);
    d = along * e + across * (ng.n % e);
    const double ba = b[(exit + 1) % 3], bb = b[(exit + 2) % 3];
    b[0] = b[1] = b[2] = 0;
    b[corner_in(ng, va)] = ba;
    b[corner_in(ng, vb)] = bb;
    f = next;
    out.faces.push_back(f);
  }
  return finish(f, b);
}

std::vector<int> node_voronoi_cells(const TriMesh& mesh, const std::vector<int>& sources) {
  const int n = static_cast<int>(mesh.n_vertices());
  std::vector<double> dist(n, std::numeric_limits<double>::infinity());
  std::vector<int> cell(n, -1);
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  for (int s = 0; s < static_cast<int>(sources.size()); ++s) {
    dist[sources[s]] = 0;
    cell[sources[s]] = s;
    queue.emplace(0.0, sources[s]);
  }
  while (!queue.empty()) {
    const auto [dv, v] = queue.top();
    queue.pop();
    if (dv > dist[v]) continue;
    const auto vh = mesh.vertex_handle(v);
    for (auto wh : mesh.vv_range(vh)) {
      const double nd = dv + (mesh.point(wh) - mesh.point(vh)).norm();
      if (nd < dist[wh.idx()]) {
        dist[wh.idx()] = nd;
        cell[wh.idx()] = cell[v];
        queue.emplace(nd, wh.idx());
      }
    }
  }
  return cell;
}

}  // namespace qs
