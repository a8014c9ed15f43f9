// Helpers of the working-mesh tests: deterministic random numbers, random surface points, and
// the invariant checks of W (exactness against the input, topology), all computed from the
// input and W alone.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <random>
#include <set>
#include <string>

#include "core/base/errors.h"
#include "core/mesh/mesh_checks.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/working_mesh.h"
#include "tests/fixtures.h"

namespace qs::test {

using VH = OpenMesh::VertexHandle;
using FH = OpenMesh::FaceHandle;
using EH = OpenMesh::EdgeHandle;
using Bary = std::array<double, 3>;

// Deterministic random numbers from mt19937's raw output (the standard fixes its sequence; the
// standard distributions are implementation-defined).
class Rng {
 public:
  explicit Rng(uint32_t seed) : gen_(seed) {}
  double uniform() { return gen_() / 4294967296.0; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  int index(int n) { return static_cast<int>(uniform() * n); }

 private:
  std::mt19937 gen_;
};

inline std::shared_ptr<const TriMesh> share(TriMesh mesh) {
  return std::make_shared<const TriMesh>(std::move(mesh));
}

inline std::shared_ptr<const TriMesh> ellipsoid_mesh() {
  return share(load_mesh(assets_dir() + "/example/ellipsoid.obj"));
}

inline std::array<Vec3, 3> input_corner_points(const TriMesh& in, int f) {
  std::array<Vec3, 3> p;
  int k = 0;
  for (auto v : in.fv_range(FH(f))) p[k++] = in.point(v);
  return p;
}

inline std::array<int, 3> face_corners(const TriMesh& m, int f) {
  std::array<int, 3> c{};
  int k = 0;
  for (auto v : m.fv_range(FH(f))) c[k++] = v.idx();
  return c;
}

// Σ b_k P_k over the input face's corners (all three terms, unlike WorkingMesh::position).
inline Vec3 from_bary(const TriMesh& in, int f, const Bary& b) {
  const auto p = input_corner_points(in, f);
  return b[0] * p[0] + b[1] * p[1] + b[2] * p[2];
}

inline double diagonal(const TriMesh& m) {
  Vec3 lo(1e300, 1e300, 1e300), hi(-1e300, -1e300, -1e300);
  for (auto v : m.vertices()) {
    lo.minimize(m.point(v));
    hi.maximize(m.point(v));
  }
  return (hi - lo).norm();
}

inline double triangle_area(const Vec3& a, const Vec3& b, const Vec3& c) {
  return 0.5 * OpenMesh::cross(b - a, c - a).norm();
}

inline double face_area(const TriMesh& m, int f) {
  const auto c = face_corners(m, f);
  return triangle_area(m.point(VH(c[0])), m.point(VH(c[1])), m.point(VH(c[2])));
}

inline double min_angle_deg(const Vec3& a, const Vec3& b, const Vec3& c) {
  auto angle = [](const Vec3& u, const Vec3& v) {
    return std::atan2(OpenMesh::cross(u, v).norm(), OpenMesh::dot(u, v)) * 180 / M_PI;
  };
  return std::min({angle(b - a, c - a), angle(a - b, c - b), angle(a - c, b - c)});
}

inline double face_min_angle(const TriMesh& m, int f) {
  const auto c = face_corners(m, f);
  return min_angle_deg(m.point(VH(c[0])), m.point(VH(c[1])), m.point(VH(c[2])));
}

// Orientation of three barycentric points (twice the signed area fraction of the host).
inline double orient(const Bary& a, const Bary& b, const Bary& c) {
  return (b[1] - a[1]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[1] - a[1]);
}

inline int zeros(const Bary& b) {
  return (b[0] == 0) + (b[1] == 0) + (b[2] == 0);
}

// Every exactness invariant of W, checked from the input and W alone.
inline void expect_exact(const WorkingMesh& wm, const std::string& where) {
  SCOPED_TRACE(where);
  const TriMesh& in = wm.input();
  const TriMesh& w = wm.mesh();
  const double diag = diagonal(in);
  const int n = static_cast<int>(in.n_vertices());
  ASSERT_EQ(wm.input_vertices(), n);
  // Vertices reproduced from their origins; input vertices not moved.
  int bad_vertices = 0;
  for (auto v : w.vertices()) {
    const SurfacePoint& o = wm.origin(v.idx());
    const double err = (w.point(v) - from_bary(in, o.face, o.bary)).norm();
    if (!(err <= 1e-12 * diag)) ++bad_vertices;
    if (v.idx() < n && w.point(v) != in.point(v)) ++bad_vertices;
    if (v.idx() >= n) {
      const int z = zeros(o.bary);
      const auto carrier = wm.carrier(v.idx());
      if (z > 1 || (z == 1) != (carrier == WorkingMesh::Carrier::kInputEdge)) ++bad_vertices;
    }
  }
  EXPECT_EQ(bad_vertices, 0) << "vertices off their origin, moved input vertices, or carriers";
  EXPECT_LE(wm.max_origin_error(), 1e-12);
  // Every face lies in its host with positive orientation; the faces of a host tile it.
  std::vector<double> host_area(in.n_faces(), 0.0);
  double area = 0;
  int bad_faces = 0;
  int live = 0;
  for (auto f : w.faces()) {
    ++live;
    const int h = wm.host(f.idx());
    const auto c = face_corners(w, f.idx());
    std::array<Bary, 3> b;
    bool ok = true;
    for (int k = 0; k < 3; ++k) {
      const auto bk = wm.bary_in_input_face(c[k], h);
      if (!bk) {
        ok = false;
        break;
      }
      b[k] = *bk;
      for (double x : b[k]) ok = ok && x >= -1e-12;
      ok = ok && (from_bary(in, h, b[k]) - w.point(VH(c[k]))).norm() <= 1e-12 * diag;
    }
    ok = ok && orient(b[0], b[1], b[2]) > 0;
    if (!ok) ++bad_faces;
    const double a = face_area(w, f.idx());
    host_area[h] += a;
    area += a;
  }
  EXPECT_EQ(bad_faces, 0) << "faces outside their host or inverted";
  EXPECT_EQ(live, wm.live_faces());
  double input_area = 0;
  int bad_hosts = 0;
  size_t hosted = 0;
  for (auto f : in.faces()) {
    const auto p = input_corner_points(in, f.idx());
    const double a = triangle_area(p[0], p[1], p[2]);
    input_area += a;
    if (!(std::abs(host_area[f.idx()] - a) <= 1e-10 * a)) ++bad_hosts;
    for (int g : wm.hosted_faces(f.idx())) {
      if (w.status(FH(g)).deleted() || wm.host(g) != f.idx()) ++bad_hosts;
    }
    hosted += wm.hosted_faces(f.idx()).size();
  }
  EXPECT_EQ(bad_hosts, 0) << "host areas or hosted_faces inconsistent";
  EXPECT_EQ(hosted, static_cast<size_t>(live));
  EXPECT_NEAR(area, input_area, 1e-12 * input_area);
}

// Manifold, with the input's Euler characteristic, boundary loops and components; no garbage.
inline void expect_topology(const WorkingMesh& wm, const std::string& where) {
  SCOPED_TRACE(where);
  const TriMesh& w = wm.mesh();
  MeshReport a, b;
  count_topology(wm.input(), a);
  count_topology(w, b);
  EXPECT_EQ(b.euler_characteristic, a.euler_characteristic);
  EXPECT_EQ(b.boundary_loops, a.boundary_loops);
  EXPECT_EQ(b.components, a.components);
  int nonmanifold = 0, deleted = 0;
  for (auto v : w.all_vertices()) {
    if (w.status(v).deleted()) ++deleted;
    if (!w.is_manifold(v) || w.is_isolated(v)) ++nonmanifold;
  }
  for (auto f : w.all_faces()) deleted += w.status(f).deleted();
  for (auto e : w.all_edges()) deleted += w.status(e).deleted();
  EXPECT_EQ(nonmanifold, 0);
  EXPECT_EQ(deleted, 0);
  for (int v = 0; v < wm.input_vertices(); ++v) {
    ASSERT_EQ(w.point(VH(v)), wm.input().point(VH(v))) << "input vertex " << v;
  }
}

inline SurfacePoint random_point(const TriMesh& in, Rng& rng) {
  SurfacePoint p;
  p.face = rng.index(static_cast<int>(in.n_faces()));
  const double r = rng.uniform();
  const int k = rng.index(3);
  if (r < 0.05) {
    p.bary = {0, 0, 0};
    p.bary[k] = 1;  // an input vertex
  } else if (r < 0.2) {
    const double t = rng.uniform(0.02, 0.98);  // on an input edge
    p.bary[k] = 0;
    p.bary[(k + 1) % 3] = t;
    p.bary[(k + 2) % 3] = 1 - t;
  } else if (r < 0.25) {
    p.bary[k] = 0;  // an input edge midpoint
    p.bary[(k + 1) % 3] = 0.5;
    p.bary[(k + 2) % 3] = 0.5;
  } else {
    double u = rng.uniform(), v = rng.uniform();
    if (u + v > 1) {
      u = 1 - u;
      v = 1 - v;
    }
    p.bary = {1 - u - v, u, v};
  }
  return p;
}

inline int random_live(Rng& rng, int count, const std::function<bool(int)>& live) {
  for (int tries = 0; tries < 100; ++tries) {
    const int i = rng.index(count);
    if (live(i)) return i;
  }
  return -1;
}

// An input halfedge with a face, whose edge is (not) on the boundary.
inline OpenMesh::HalfedgeHandle input_halfedge(const TriMesh& in, bool boundary) {
  for (auto h : in.halfedges()) {
    if (!h.face().is_valid()) continue;
    if (in.is_boundary(h.edge()) == boundary) return h;
  }
  return OpenMesh::HalfedgeHandle();
}

inline SurfacePoint point_on_halfedge(const TriMesh& in, OpenMesh::HalfedgeHandle h, double t) {
  SurfacePoint p;
  p.face = in.face_handle(h).idx();
  const auto c = face_corners(in, p.face);
  for (int k = 0; k < 3; ++k) {
    p.bary[k] = c[k] == in.from_vertex_handle(h).idx() ? 1 - t
                : c[k] == in.to_vertex_handle(h).idx() ? t
                                                       : 0.0;
  }
  return p;
}

inline std::set<int> neighbours(const TriMesh& m, int v) {
  std::set<int> out;
  for (auto w : m.vv_range(VH(v))) out.insert(w.idx());
  return out;
}

inline double star_min_angle(const TriMesh& m, int v) {
  double worst = 180;
  for (auto f : m.vf_range(VH(v))) worst = std::min(worst, face_min_angle(m, f.idx()));
  return worst;
}

inline std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InvalidInputError& e) {
    return e.what();
  }
  return "(no InvalidInputError)";
}

}  // namespace qs::test
