// WorkingMesh: flips, vertex moves, vertex removal, compaction, Delaunay improvement and
// measures (construction, queries and splits are in working_mesh.cpp).
#include <algorithm>
#include <cmath>
#include <deque>
#include <string>

#include "core/base/errors.h"
#include "core/mesh/working_mesh.h"

namespace qs {

namespace {

using VH = OpenMesh::VertexHandle;
using FH = OpenMesh::FaceHandle;
using EH = OpenMesh::EdgeHandle;
using HH = OpenMesh::HalfedgeHandle;

double corner_angle(const Vec3& at, const Vec3& a, const Vec3& b) {
  const Vec3 u = a - at, v = b - at;
  return std::atan2(OpenMesh::cross(u, v).norm(), OpenMesh::dot(u, v));
}

}  // namespace

bool WorkingMesh::flip_edge(int edge) {
  check_edge(edge, "flip_edge");
  const EH e(edge);
  if (mesh_.is_boundary(e)) return false;
  const HH h0 = mesh_.halfedge_handle(e, 0), h1 = mesh_.halfedge_handle(e, 1);
  const int fa = mesh_.face_handle(h0).idx(), fb = mesh_.face_handle(h1).idx();
  const int h = host_[fa];
  if (host_[fb] != h || !mesh_.is_flip_ok(e)) return false;
  // Faces (a, b, c) and (b, a, d) become (a, d, c) and (d, b, c).
  const int a = mesh_.from_vertex_handle(h0).idx(), b = mesh_.to_vertex_handle(h0).idx();
  const int c = mesh_.to_vertex_handle(mesh_.next_halfedge_handle(h0)).idx();
  const int d = mesh_.to_vertex_handle(mesh_.next_halfedge_handle(h1)).idx();
  const Bary ba = host_bary(a, h), bb = host_bary(b, h), bc = host_bary(c, h), bd = host_bary(d, h);
  if (!(det3(ba, bd, bc) > kMinDet) || !(det3(bd, bb, bc) > kMinDet)) return false;
  mesh_.flip(e);
  return true;
}

bool WorkingMesh::can_move_vertex(int v, const SurfacePoint& p_in) const {
  check_vertex(v, "can_move_vertex");
  const SurfacePoint p = checked_point(p_in, "can_move_vertex");
  if (is_input_vertex(v)) return false;
  const SurfacePoint& o = origin_[v];
  const int zeros = zero_count(p.bary);
  if (zero_count(o.bary) == 0) {
    if (p.face != o.face || zeros != 0) return false;
  } else {
    if (zeros != 1) return false;
    const auto pe = point_in_input_face(p, o.face);
    if (!pe) return false;
    for (int k = 0; k < 3; ++k) {
      if (((*pe)[k] == 0) != (o.bary[k] == 0)) return false;
    }
  }
  const Vec3 x = position(p);
  double old_angle = 180, new_angle = 180;
  for (auto f : mesh_.vf_range(VH(v))) {
    const int h = host_[f.idx()];
    const auto pb = point_in_input_face(p, h);
    if (!pb) return false;
    const auto c = corners(f.idx());
    std::array<Bary, 3> b;
    std::array<Vec3, 3> xs;
    for (int k = 0; k < 3; ++k) {
      b[k] = c[k] == v ? *pb : host_bary(c[k], h);
      xs[k] = c[k] == v ? x : mesh_.point(VH(c[k]));
    }
    if (!(det3(b[0], b[1], b[2]) > kMinDet)) return false;
    old_angle = std::min(old_angle, face_min_angle_deg(f.idx()));
    new_angle = std::min(new_angle, triangle_min_angle_deg(xs[0], xs[1], xs[2]));
  }
  return new_angle >= std::min(options_.min_angle_deg, old_angle);
}

bool WorkingMesh::move_vertex(int v, const SurfacePoint& p) {
  if (!can_move_vertex(v, p)) return false;
  origin_[v] = checked_point(p, "move_vertex");
  mesh_.set_point(VH(v), position(origin_[v]));
  return true;
}

bool WorkingMesh::remove_vertex(int v, double min_angle_deg) {
  check_vertex(v, "remove_vertex");
  if (is_input_vertex(v)) return false;
  const SurfacePoint& o = origin_[v];
  int zero = -1;
  for (int k = 0; k < 3; ++k) {
    if (o.bary[k] == 0) zero = k;
  }
  HH best;
  double best_angle = -1;
  for (auto h : mesh_.voh_range(VH(v))) {
    const int u = h.to().idx();
    if (zero >= 0) {
      // A vertex on an input edge collapses only along that edge.
      const auto bu = point_in_input_face(origin_[u], o.face);
      if (!bu || (*bu)[zero] != 0) continue;
    }
    if (!mesh_.is_collapse_ok(h)) continue;
    bool ok = true;
    double angle = 180;
    for (auto f : mesh_.vf_range(VH(v))) {
      const auto c = corners(f.idx());
      if (std::find(c.begin(), c.end(), u) != c.end()) continue;  // removed with the edge
      const int hf = host_[f.idx()];
      std::array<Bary, 3> b;
      std::array<Vec3, 3> xs;
      for (int k = 0; k < 3; ++k) {
        const int w = c[k] == v ? u : c[k];
        b[k] = host_bary(w, hf);
        xs[k] = mesh_.point(VH(w));
      }
      if (!(det3(b[0], b[1], b[2]) > kMinDet)) {
        ok = false;
        break;
      }
      angle = std::min(angle, triangle_min_angle_deg(xs[0], xs[1], xs[2]));
    }
    if (ok && angle > best_angle) {
      best_angle = angle;
      best = h;
    }
  }
  if (!best.is_valid()) return false;
  // A collapse never makes the mesh worse than the quality bar where it was not already.
  double old_angle = 180;
  for (auto f : mesh_.vf_range(VH(v))) old_angle = std::min(old_angle, face_min_angle_deg(f.idx()));
  const double bar = min_angle_deg >= 0 ? min_angle_deg : options_.min_angle_deg;
  if (best_angle < std::min(bar, old_angle)) return false;
  std::vector<int> star;
  for (auto f : mesh_.vf_range(VH(v))) star.push_back(f.idx());
  mesh_.collapse(best);
  for (int f : star) {
    if (mesh_.status(FH(f)).deleted()) {
      remove_hosted(f);
      --live_faces_;
    }
  }
  return true;
}

WorkingMesh::Compaction WorkingMesh::compact() {
  Compaction out;
  OpenMesh::VPropHandleT<int> vold;
  OpenMesh::EPropHandleT<int> eold;
  OpenMesh::FPropHandleT<int> fold;
  mesh_.add_property(vold);
  mesh_.add_property(eold);
  mesh_.add_property(fold);
  for (auto v : mesh_.all_vertices()) mesh_.property(vold, v) = v.idx();
  for (auto e : mesh_.all_edges()) mesh_.property(eold, e) = e.idx();
  for (auto f : mesh_.all_faces()) mesh_.property(fold, f) = f.idx();
  out.vertex.assign(mesh_.n_vertices(), -1);
  out.edge.assign(mesh_.n_edges(), -1);
  out.face.assign(mesh_.n_faces(), -1);
  mesh_.garbage_collection();
  std::vector<SurfacePoint> origin(mesh_.n_vertices());
  for (auto v : mesh_.all_vertices()) {
    const int old = mesh_.property(vold, v);
    out.vertex[old] = v.idx();
    origin[v.idx()] = origin_[old];
  }
  for (auto e : mesh_.all_edges()) out.edge[mesh_.property(eold, e)] = e.idx();
  std::vector<int> host(mesh_.n_faces());
  for (auto f : mesh_.all_faces()) {
    const int old = mesh_.property(fold, f);
    out.face[old] = f.idx();
    host[f.idx()] = host_[old];
  }
  mesh_.remove_property(vold);
  mesh_.remove_property(eold);
  mesh_.remove_property(fold);
  for (int v = 0; v < n_input_; ++v) {
    if (out.vertex[v] != v) {
      throw QsError("working mesh: internal error, compaction moved input vertex " +
                    std::to_string(v));
    }
  }
  origin_ = std::move(origin);
  for (auto& list : hosted_) list.clear();
  host_.clear();
  slot_.clear();
  for (int f = 0; f < static_cast<int>(host.size()); ++f) add_hosted(f, host[f]);
  live_faces_ = static_cast<int>(mesh_.n_faces());
  return out;
}

int WorkingMesh::improve(const std::vector<int>& faces, const std::function<bool(int)>& protect) {
  std::vector<char> queued(mesh_.n_edges(), 0);
  std::deque<int> queue;
  auto push = [&](int e) {
    if (e >= static_cast<int>(queued.size())) queued.resize(e + 1, 0);
    if (queued[e] || mesh_.status(EH(e)).deleted()) return;
    queued[e] = 1;
    queue.push_back(e);
  };
  auto push_face = [&](int f) {
    for (auto e : mesh_.fe_range(FH(f))) push(e.idx());
  };
  if (faces.empty()) {
    for (auto f : mesh_.faces()) push_face(f.idx());
  } else {
    for (int f : faces) {
      check_face(f, "improve");
      push_face(f);
    }
  }
  // Lawson flips terminate in a planar constrained triangulation; the cap only guards
  // against rounding making the criterion cycle.
  const long cap = 20L * static_cast<long>(mesh_.n_edges()) + 1000;
  int flips = 0;
  for (long step = 0; !queue.empty() && step < cap; ++step) {
    const int e = queue.front();
    queue.pop_front();
    queued[e] = 0;
    if (mesh_.is_boundary(EH(e)) || (protect && protect(e))) continue;
    const HH h0 = mesh_.halfedge_handle(EH(e), 0), h1 = mesh_.halfedge_handle(EH(e), 1);
    const int fa = mesh_.face_handle(h0).idx(), fb = mesh_.face_handle(h1).idx();
    if (host_[fa] != host_[fb]) continue;
    const Vec3 a = mesh_.point(mesh_.from_vertex_handle(h0));
    const Vec3 b = mesh_.point(mesh_.to_vertex_handle(h0));
    const Vec3 c = mesh_.point(mesh_.to_vertex_handle(mesh_.next_halfedge_handle(h0)));
    const Vec3 d = mesh_.point(mesh_.to_vertex_handle(mesh_.next_halfedge_handle(h1)));
    if (corner_angle(c, a, b) + corner_angle(d, a, b) <= M_PI + 1e-10) continue;
    if (!flip_edge(e)) continue;
    ++flips;
    push_face(fa);
    push_face(fb);
  }
  return flips;
}

double WorkingMesh::growth() const {
  return static_cast<double>(live_faces_) / static_cast<double>(input_->n_faces());
}

double WorkingMesh::max_origin_error() const {
  double worst = 0;
  for (auto v : mesh_.vertices()) {
    worst = std::max(worst, (mesh_.point(v) - position(origin_[v.idx()])).norm());
  }
  return bbox_diagonal_ > 0 ? worst / bbox_diagonal_ : worst;
}

double WorkingMesh::min_angle_deg() const {
  double worst = 180;
  for (auto f : mesh_.faces()) worst = std::min(worst, face_min_angle_deg(f.idx()));
  return worst;
}

}  // namespace qs
