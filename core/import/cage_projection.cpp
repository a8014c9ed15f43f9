#include "core/import/cage_projection.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "core/base/errors.h"
#include "core/mesh/closest_point.h"

namespace qs {

namespace {

using VH = OpenMesh::VertexHandle;
using HH = OpenMesh::HalfedgeHandle;
using FH = OpenMesh::FaceHandle;

// The target's boundary edges, for closest points on the boundary (linear scan: boundaries are
// short next to the surface).
class BoundaryPoints {
 public:
  explicit BoundaryPoints(const TriMesh& target) : target_(target) {
    for (const auto h : target.halfedges()) {
      if (!target.is_boundary(h)) continue;
      edges_.push_back(target.opposite_halfedge_handle(h));  // the halfedge inside a face
    }
  }
  bool empty() const { return edges_.empty(); }

  // The closest point of the boundary to \p p, as a point of the boundary edge's face with an
  // exact zero for the corner off the edge.
  SurfacePoint closest(const Vec3& p, Vec3* at) const {
    double best = std::numeric_limits<double>::infinity();
    SurfacePoint out;
    for (const HH h : edges_) {
      const Vec3& a = target_.point(target_.from_vertex_handle(h));
      const Vec3& b = target_.point(target_.to_vertex_handle(h));
      const Vec3 d = b - a;
      const double l2 = d.sqrnorm();
      const double t = l2 > 0 ? std::clamp(((p - a) | d) / l2, 0.0, 1.0) : 0.0;
      const Vec3 q = a + t * d;
      const double dist = (p - q).sqrnorm();
      if (dist >= best) continue;
      best = dist;
      *at = q;
      const FH f = target_.face_handle(h);
      out.face = f.idx();
      out.bary = {0, 0, 0};
      int k = 0;
      for (const auto v : target_.fv_range(f)) {
        if (v == target_.from_vertex_handle(h)) out.bary[k] = 1 - t;
        if (v == target_.to_vertex_handle(h)) out.bary[k] = t;
        ++k;
      }
    }
    return out;
  }

 private:
  const TriMesh& target_;
  std::vector<HH> edges_;
};

bool on_target_boundary(const TriMesh& target, const SurfacePoint& p) {
  const FH f(p.face);
  int k = 0;
  std::array<VH, 3> corner;
  for (const auto v : target.fv_range(f)) corner[k++] = v;
  for (int j = 0; j < 3; ++j) {
    if (p.bary[j] != 0) continue;
    const HH h = target.find_halfedge(corner[(j + 1) % 3], corner[(j + 2) % 3]);
    if (h.is_valid() && target.is_boundary(target.edge_handle(h))) return true;
  }
  for (int j = 0; j < 3; ++j)
    if (p.bary[j] == 1 && target.is_boundary(corner[j])) return true;
  return false;
}

Vec3 unit_face_normal(const TriMesh& mesh, int f) {
  std::array<Vec3, 3> p;
  int k = 0;
  for (const auto v : mesh.fv_range(FH(f))) p[k++] = mesh.point(v);
  const Vec3 n = (p[1] - p[0]) % (p[2] - p[0]);
  const double l = n.norm();
  return l > 0 ? n / l : Vec3(0, 0, 0);
}

// The target surface for projections: closest points, boundary points, face normals.
class Surface {
 public:
  explicit Surface(const TriMesh& target) : target_(target), tree_(target), boundary_(target) {
    normal_.resize(target.n_faces());
    for (const auto f : target.faces()) normal_[f.idx()] = unit_face_normal(target, f.idx());
    vertex_normal_.assign(target.n_vertices(), Vec3(0, 0, 0));
    for (const auto f : target.faces())
      for (const auto v : target.fv_range(f)) vertex_normal_[v.idx()] += normal_[f.idx()];
    for (Vec3& n : vertex_normal_)
      if (n.norm() > 0) n.normalize();
  }
  bool has_boundary() const { return !boundary_.empty(); }

  // The target's normal at p: its face's; on an edge the mean of the two faces' normals, at a
  // vertex the mean of the faces' around it (a point on a sharp edge faces both ways).
  Vec3 normal(const SurfacePoint& p) const {
    int zeros = 0, nonzero = -1;
    for (int k = 0; k < 3; ++k) {
      if (p.bary[k] == 0)
        ++zeros;
      else
        nonzero = k;
    }
    if (zeros == 0) return normal_[p.face];
    std::array<VH, 3> corner;
    int k = 0;
    for (const auto v : target_.fv_range(FH(p.face))) corner[k++] = v;
    if (zeros == 2) return vertex_normal_[corner[nonzero].idx()];
    int zero = 0;
    while (p.bary[zero] != 0) ++zero;
    const HH h = target_.find_halfedge(corner[(zero + 1) % 3], corner[(zero + 2) % 3]);
    const FH other = target_.opposite_face_handle(h);
    if (!other.is_valid()) return normal_[p.face];
    const Vec3 n = normal_[p.face] + normal_[other.idx()];
    return n.norm() > 0 ? n.normalized() : normal_[p.face];
  }

  // The closest point to x: of the boundary when on_boundary, else of the surface among the
  // faces whose normal points along \p facing (all faces when none does, or facing is 0), moved
  // into its face (a tenth of the way to the centroid) when it lies on the boundary.
  void project(const Vec3& x, bool on_boundary, const Vec3& facing, SurfacePoint& p,
               Vec3& at) const {
    if (on_boundary) {
      p = boundary_.closest(x, &at);
      return;
    }
    ClosestPoint cp;
    if (facing.sqrnorm() > 0)
      cp = tree_.closest(x, [&](int f) { return (normal_[f] | facing) > 0; });
    if (cp.face < 0) cp = tree_.closest(x);
    p.face = cp.face;
    p.bary = cp.bary;
    at = cp.point;
    if (!on_target_boundary(target_, p)) return;
    for (double& b : p.bary) b = 0.9 * b + 0.1 / 3;
    std::array<Vec3, 3> c;
    int k = 0;
    for (const auto v : target_.fv_range(FH(p.face))) c[k++] = target_.point(v);
    at = p.bary[0] * c[0] + p.bary[1] * c[1] + p.bary[2] * c[2];
  }
  SurfacePoint boundary_point(const Vec3& x) const {
    Vec3 at;
    return boundary_.closest(x, &at);
  }

 private:
  const TriMesh& target_;
  ClosestPointTree tree_;
  BoundaryPoints boundary_;
  std::vector<Vec3> normal_, vertex_normal_;
};

// The projected face's (Newell) normal against the target's normals at its corners; 0 when
// the face collapsed.
double face_sign(const PolyMesh& m, FH f, const ProjectedCage& p, const Surface& surface) {
  Vec3 newell(0, 0, 0), ns(0, 0, 0);
  double perimeter = 0;
  for (const auto h : m.fh_range(f)) {
    const int a = m.from_vertex_handle(h).idx(), b = m.to_vertex_handle(h).idx();
    newell += p.position[a] % p.position[b];
    perimeter += (p.position[b] - p.position[a]).norm();
    ns += surface.normal(p.point[a]);
  }
  if (!(newell.norm() > 1e-12 * perimeter * perimeter)) return 0;
  return newell | ns;
}

// Whether the first neighbours of v wind once around it in the cage's order (\p expected: +1,
// or -1 for a target oriented against the cage). The turn from each neighbour to the next is
// measured through the face between them, triangle by triangle through its far corners (so
// that straight and concave corners are not ambiguous): each triangle (v, p, q) turns by its
// angle at v, signed by its orientation against the target's normals at its corners (a face
// over a sharp edge of the target has no single tangent plane). Every face must turn the
// expected way, and together less than two turns (less than 3π: curved surfaces have other
// angle sums than 2π), or less than a full turn at a boundary vertex.
bool winds_once(const PolyMesh& m, int v, const ProjectedCage& p, const Surface& surface,
                double expected) {
  const Vec3& centre = p.position[v];
  const Vec3 nv = surface.normal(p.point[v]);
  double turn = 0;
  for (const HH h : m.voh_range(VH(v))) {
    if (m.is_boundary(h)) continue;  // the exterior wedge of a boundary vertex
    double wedge = 0;
    int last = m.to_vertex_handle(h).idx();
    for (HH g = m.next_halfedge_handle(h); m.to_vertex_handle(g).idx() != v;
         g = m.next_halfedge_handle(g)) {
      const int u = m.to_vertex_handle(g).idx();
      const Vec3 a = p.position[last] - centre, b = p.position[u] - centre;
      const Vec3 n = nv + surface.normal(p.point[last]) + surface.normal(p.point[u]);
      const Vec3 cross = a % b;
      const double angle = std::atan2(cross.norm(), a | b);
      const double side = cross | n;
      if (!(a.norm() > 0) || !(b.norm() > 0)) return false;
      if (side == 0 && angle > 0) return false;  // straight back: no way to tell the side
      wedge += side >= 0 ? angle : -angle;
      last = u;
    }
    if (!(wedge * expected > 0)) return false;
    turn += wedge;
  }
  const double full = 2 * std::numbers::pi;
  return std::abs(turn) < (m.is_boundary(VH(v)) ? full : 1.5 * full);
}

// +1 when most projected faces agree with the target's normals, else -1.
double orientation(const PolyMesh& m, const ProjectedCage& p, const Surface& surface) {
  long positive = 0, negative = 0;
  for (const auto f : m.faces()) {
    const double s = face_sign(m, f, p, surface);
    positive += s > 0;
    negative += s < 0;
  }
  return negative > positive ? -1.0 : 1.0;
}

// Vertices of folded faces and vertices whose neighbours do not wind once around them.
std::vector<int> folded_vertices(const PolyMesh& m, const ProjectedCage& p, const Surface& surface,
                                 double expected) {
  std::vector<char> bad(m.n_vertices(), 0);
  for (const auto f : m.faces()) {
    if (face_sign(m, f, p, surface) * expected > 0) continue;
    for (const auto v : m.fv_range(f)) bad[v.idx()] = 1;
  }
  for (const auto v : m.vertices())
    if (!bad[v.idx()] && !winds_once(m, v.idx(), p, surface, expected)) bad[v.idx()] = 1;
  std::vector<int> out;
  for (size_t v = 0; v < bad.size(); ++v)
    if (bad[v]) out.push_back(static_cast<int>(v));
  return out;
}

// Relaxes the projection where it folds: the folded vertices and a few rings around them (more
// with every round) move to the mean of their neighbours (boundary vertices: of their boundary
// neighbours, sliding along the target's boundary) and back onto the surface, a few sweeps a
// round, until nothing folds or the rounds are used up. \p pinned vertices (none when empty)
// stay; \p moved marks the vertices moved. Returns the number of vertices still folded.
int relax_folds(const PolyMesh& m, ProjectedCage& p, const Surface& surface,
                const std::vector<Vec3>& facing, double expected, int rounds,
                const std::vector<char>& pinned, std::vector<char>& moved) {
  const int nv = static_cast<int>(m.n_vertices());
  std::vector<char> in_region(nv, 0);
  for (int round = 0; round < rounds; ++round) {
    std::vector<int> region = folded_vertices(m, p, surface, expected);
    if (region.empty()) break;
    std::fill(in_region.begin(), in_region.end(), 0);
    for (int v : region) in_region[v] = 1;
    const int rings = 1 + round / 3;
    for (int r = 0; r < rings; ++r) {
      const size_t size = region.size();
      for (size_t i = 0; i < size; ++i) {
        for (const auto u : m.vv_range(VH(region[i]))) {
          if (in_region[u.idx()]) continue;
          in_region[u.idx()] = 1;
          region.push_back(u.idx());
        }
      }
    }
    for (int sweep = 0; sweep < 3; ++sweep) {
      for (int v : region) {
        if (!pinned.empty() && pinned[v]) continue;
        const bool boundary = m.is_boundary(VH(v));
        Vec3 sum(0, 0, 0);
        int n = 0;
        for (const auto u : m.vv_range(VH(v))) {
          if (boundary && !m.is_boundary(m.edge_handle(m.find_halfedge(VH(v), u)))) continue;
          sum += p.position[u.idx()];
          ++n;
        }
        if (n == 0) continue;
        surface.project(sum / n, boundary, facing[v], p.point[v], p.position[v]);
        moved[v] = 1;
      }
    }
  }
  return static_cast<int>(folded_vertices(m, p, surface, expected).size());
}

}  // namespace

ProjectedCage project_cage(const DenseCage& cage, const TriMesh& target,
                           const CageProjectionOptions& options) {
  const PolyMesh& dense = cage.mesh;
  if (!(options.flow_offset > 0 && options.flow_offset <= 100))
    throw InvalidInputError("projection: flow_offset must be in (0, 100]");
  if (options.flow_steps < 1 || options.flow_steps > 1000)
    throw InvalidInputError("projection: flow_steps must be in [1, 1000]");
  if (options.relax_rounds < 0 || options.relax_rounds > 1000)
    throw InvalidInputError("projection: relax_rounds must be in [0, 1000]");
  const int nv = static_cast<int>(dense.n_vertices());
  const Surface surface(target);
  std::vector<char> on_boundary(nv, 0);
  for (const auto v : dense.vertices()) on_boundary[v.idx()] = dense.is_boundary(v);
  if (!surface.has_boundary() &&
      std::find(on_boundary.begin(), on_boundary.end(), 1) != on_boundary.end())
    throw InvalidInputError("the quad mesh has a boundary, the target mesh has none");

  ProjectedCage out;
  out.point.resize(nv);
  out.position.resize(nv);
  // Each vertex goes to faces of the target that face the way the cage faces there (so that
  // it does not snap onto the far side of a thin part); which way that is, the plain closest
  // points decide (the target may be oriented against the cage).
  std::vector<Vec3> facing(nv, Vec3(0, 0, 0));
  auto project_all = [&](const std::vector<Vec3>& x) {
    for (int v = 0; v < nv; ++v)
      surface.project(x[v], on_boundary[v], facing[v], out.point[v], out.position[v]);
  };
  std::vector<Vec3> x(nv);
  for (const auto v : dense.vertices()) x[v.idx()] = dense.point(v);
  project_all(x);
  {
    const double sign = orientation(dense, out, surface);
    for (const auto f : dense.faces()) {
      Vec3 newell(0, 0, 0);
      for (const auto h : dense.fh_range(f))
        newell += dense.point(dense.from_vertex_handle(h)) % dense.point(dense.to_vertex_handle(h));
      for (const auto v : dense.fv_range(f)) facing[v.idx()] += sign * newell;
    }
    project_all(x);
  }
  out.offset.resize(nv);
  for (const auto v : dense.vertices()) {
    double edge = 0;
    int n = 0;
    for (const auto h : dense.voh_range(v)) {
      edge += dense.calc_edge_length(h);
      ++n;
    }
    out.offset[v.idx()] = (out.position[v.idx()] - x[v.idx()]).norm();
    if (n > 0 && edge > 0)
      out.max_relative_offset = std::max(out.max_relative_offset, out.offset[v.idx()] * n / edge);
  }

  if (out.max_relative_offset > options.flow_offset) {
    // The flow: each step moves every vertex by a share of its displacement to the surface,
    // averaged with its neighbours' (a smooth motion keeps neighbours in order), the last step
    // the whole remaining way; boundary vertices follow their own displacement.
    const int steps = options.flow_steps;
    std::vector<Vec3> disp(nv), smooth(nv);
    for (int s = 0; s < steps; ++s) {
      for (int v = 0; v < nv; ++v) disp[v] = out.position[v] - x[v];
      for (int round = 0; round < 2; ++round) {
        for (const auto v : dense.vertices()) {
          const int i = v.idx();
          if (on_boundary[i]) {
            smooth[i] = disp[i];
            continue;
          }
          Vec3 sum(0, 0, 0);
          int n = 0;
          for (const auto u : dense.vv_range(v)) {
            sum += disp[u.idx()];
            ++n;
          }
          smooth[i] = n > 0 ? 0.5 * disp[i] + 0.5 * sum / n : disp[i];
        }
        disp.swap(smooth);
      }
      const double share = 1.0 / (steps - s);
      for (int v = 0; v < nv; ++v) x[v] += share * disp[v];
      project_all(x);
    }
    out.flow_steps = steps;
  }
  // The cage's own surface where it lies on the target: each quad-structure vertex whose linear
  // position (its own) is at most as far from the target as its smoothed one (or within a
  // thousandth of its mean edge length: a flat region), then every dense vertex whose faces all
  // lie in quads with such corners only. Those vertices go to the closest points of their
  // linear positions, and stay there while the relaxation can do without moving them.
  if (cage.linear.size() != static_cast<size_t>(nv) || cage.quad_vertices > nv ||
      cage.quad_of_face.size() != dense.n_faces())
    throw InvalidInputError("projection: the dense cage is inconsistent");
  std::vector<SurfacePoint> linear_point(nv);
  std::vector<Vec3> linear_position(nv);
  std::vector<char> own(cage.quad_vertices, 0);
  for (int v = 0; v < cage.quad_vertices; ++v) {
    surface.project(cage.linear[v], on_boundary[v], facing[v], linear_point[v], linear_position[v]);
    double edge = 0;
    int n = 0;
    for (const auto h : dense.voh_range(VH(v))) {
      edge += dense.calc_edge_length(h);
      ++n;
    }
    const double offset = (linear_position[v] - cage.linear[v]).norm();
    own[v] = offset <= out.offset[v] || (n > 0 && offset <= 1e-3 * edge / n);
  }
  int quads = 0;
  for (const int q : cage.quad_of_face) quads = std::max(quads, q + 1);
  std::vector<char> quad_on(quads, 1);
  for (const auto f : dense.faces())
    for (const auto v : dense.fv_range(f))
      if (v.idx() < cage.quad_vertices && !own[v.idx()]) quad_on[cage.quad_of_face[f.idx()]] = 0;
  std::vector<char> pinned(nv, 0);
  for (const auto v : dense.vertices()) {
    const int i = v.idx();
    bool on = i < cage.quad_vertices ? own[i] : true;
    if (i >= cage.quad_vertices) {
      for (const auto f : dense.vf_range(v)) on = on && quad_on[cage.quad_of_face[f.idx()]];
      if (on)
        surface.project(cage.linear[i], on_boundary[i], facing[i], linear_point[i],
                        linear_position[i]);
    }
    if (!on) continue;
    out.point[i] = linear_point[i];
    out.position[i] = linear_position[i];
    out.offset[i] = (linear_position[i] - cage.linear[i]).norm();
    pinned[i] = 1;
  }
  const double expected = orientation(dense, out, surface);
  std::vector<char> moved(nv, 0);
  const std::vector<SurfacePoint> start_point = out.point;
  const std::vector<Vec3> start_position = out.position;
  const int folded =
      relax_folds(dense, out, surface, facing, expected, options.relax_rounds, pinned, moved);
  if (folded > 0 && std::find(pinned.begin(), pinned.end(), 1) != pinned.end()) {
    out.point = start_point;
    out.position = start_position;
    std::fill(moved.begin(), moved.end(), 0);
    relax_folds(dense, out, surface, facing, expected, options.relax_rounds, {}, moved);
  }
  out.relaxed_vertices = static_cast<int>(std::count(moved.begin(), moved.end(), 1));

  out.boundary_midpoint.resize(dense.n_edges());
  for (const auto e : dense.edges()) {
    if (!dense.is_boundary(e)) continue;
    const auto h = dense.halfedge_handle(e, 0);
    out.boundary_midpoint[e.idx()] =
        surface.boundary_point(0.5 * (out.position[dense.from_vertex_handle(h).idx()] +
                                      out.position[dense.to_vertex_handle(h).idx()]));
  }
  return out;
}

CageFolds find_folds(const DenseCage& cage, const ProjectedCage& projected, const TriMesh& target,
                     const std::vector<int>& vertices) {
  const PolyMesh& m = cage.mesh;
  const Surface surface(target);
  CageFolds out;
  const double expected = orientation(m, projected, surface);
  out.reversed = expected < 0;
  for (const auto f : m.faces()) {
    if (face_sign(m, f, projected, surface) * expected <= 0)
      out.quads.push_back(cage.quad_of_face[f.idx()]);
  }
  std::sort(out.quads.begin(), out.quads.end());
  out.quads.erase(std::unique(out.quads.begin(), out.quads.end()), out.quads.end());
  for (int v : vertices)
    if (!winds_once(m, v, projected, surface, expected)) out.vertices.push_back(v);
  std::sort(out.vertices.begin(), out.vertices.end());
  return out;
}

}  // namespace qs
