#include "core/mesh/closest_point.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace qs {

namespace {

constexpr int kLeafSize = 4;

Vec3 component_min(const Vec3& a, const Vec3& b) {
  return Vec3(std::min(a[0], b[0]), std::min(a[1], b[1]), std::min(a[2], b[2]));
}
Vec3 component_max(const Vec3& a, const Vec3& b) {
  return Vec3(std::max(a[0], b[0]), std::max(a[1], b[1]), std::max(a[2], b[2]));
}

TrianglePoint make_point(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, double u,
                         double v, double w) {
  TrianglePoint r;
  r.bary = {{u, v, w}};
  r.point = u * a + v * b + w * c;
  r.distance = (p - r.point).norm();
  return r;
}

// Closest point on segment (a, b): parameter t in [0, 1].
double segment_parameter(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 d = b - a;
  const double len_sq = d.sqrnorm();
  if (len_sq <= 0) return 0;
  return std::clamp(OpenMesh::dot(p - a, d) / len_sq, 0.0, 1.0);
}

}  // namespace

TrianglePoint closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b,
                                        const Vec3& c) {
  // Project onto the plane and test the barycentrics; when the projection falls outside (or the
  // triangle is degenerate) the closest point lies on one of the three edges.
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d00 = ab.sqrnorm(), d01 = OpenMesh::dot(ab, ac), d11 = ac.sqrnorm();
  const double d20 = OpenMesh::dot(ap, ab), d21 = OpenMesh::dot(ap, ac);
  const double denom = d00 * d11 - d01 * d01;
  if (denom > 1e-30 * (d00 * d11 + 1e-300)) {
    const double v = (d11 * d20 - d01 * d21) / denom;
    const double w = (d00 * d21 - d01 * d20) / denom;
    const double u = 1.0 - v - w;
    if (u >= 0 && v >= 0 && w >= 0) return make_point(p, a, b, c, u, v, w);
  }
  const double t_ab = segment_parameter(p, a, b);
  const double t_bc = segment_parameter(p, b, c);
  const double t_ca = segment_parameter(p, c, a);
  const TrianglePoint on_ab = make_point(p, a, b, c, 1 - t_ab, t_ab, 0);
  const TrianglePoint on_bc = make_point(p, a, b, c, 0, 1 - t_bc, t_bc);
  const TrianglePoint on_ca = make_point(p, a, b, c, t_ca, 0, 1 - t_ca);
  const TrianglePoint* best = &on_ab;
  if (on_bc.distance < best->distance) best = &on_bc;
  if (on_ca.distance < best->distance) best = &on_ca;
  return *best;
}

ClosestPointTree::ClosestPointTree(const TriMesh& mesh) {
  corners_.resize(mesh.n_faces());
  for (const auto f : mesh.faces()) {
    int k = 0;
    for (const auto v : mesh.fv_range(f)) {
      if (k < 3) corners_[f.idx()][k++] = mesh.point(v);
    }
  }
  order_.resize(corners_.size());
  for (size_t i = 0; i < order_.size(); ++i) order_[i] = static_cast<int>(i);
  if (!order_.empty()) {
    nodes_.reserve(2 * order_.size() / kLeafSize + 2);
    build(0, static_cast<int>(order_.size()));
  }
}

int ClosestPointTree::build(int begin, int end) {
  const int id = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Node node;
  node.begin = begin;
  node.end = end;
  const double inf = std::numeric_limits<double>::infinity();
  node.lo = Vec3(inf, inf, inf);
  node.hi = Vec3(-inf, -inf, -inf);
  Vec3 c_lo(inf, inf, inf), c_hi(-inf, -inf, -inf);
  for (int i = begin; i < end; ++i) {
    const auto& t = corners_[order_[i]];
    for (const Vec3& q : t) {
      node.lo = component_min(node.lo, q);
      node.hi = component_max(node.hi, q);
    }
    const Vec3 centroid = (t[0] + t[1] + t[2]) / 3.0;
    c_lo = component_min(c_lo, centroid);
    c_hi = component_max(c_hi, centroid);
  }
  if (end - begin > kLeafSize) {
    const Vec3 extent = c_hi - c_lo;
    int axis = 0;
    if (extent[1] > extent[axis]) axis = 1;
    if (extent[2] > extent[axis]) axis = 2;
    const int mid = (begin + end) / 2;
    std::nth_element(
        order_.begin() + begin, order_.begin() + mid, order_.begin() + end, [&](int f, int g) {
          const auto& a = corners_[f];
          const auto& b = corners_[g];
          return a[0][axis] + a[1][axis] + a[2][axis] < b[0][axis] + b[1][axis] + b[2][axis];
        });
    node.left = build(begin, mid);
    node.right = build(mid, end);
  }
  nodes_[id] = node;
  return id;
}

double ClosestPointTree::box_distance_sq(const Node& node, const Vec3& p) {
  double d = 0;
  for (int k = 0; k < 3; ++k) {
    const double excess = std::max({node.lo[k] - p[k], 0.0, p[k] - node.hi[k]});
    d += excess * excess;
  }
  return d;
}

ClosestPoint ClosestPointTree::closest(const Vec3& p) const {
  return closest(p, {});
}

ClosestPoint ClosestPointTree::closest(const Vec3& p,
                                       const std::function<bool(int)>& accept) const {
  ClosestPoint best;
  if (nodes_.empty()) return best;
  double best_sq = std::numeric_limits<double>::infinity();
  // Depth-first, nearer child first, pruning boxes farther than the best hit so far.
  std::vector<int> stack{0};
  stack.reserve(64);
  while (!stack.empty()) {
    const Node& node = nodes_[stack.back()];
    stack.pop_back();
    if (box_distance_sq(node, p) >= best_sq) continue;
    if (node.left < 0) {
      for (int i = node.begin; i < node.end; ++i) {
        if (accept && !accept(order_[i])) continue;
        const auto& t = corners_[order_[i]];
        const TrianglePoint q = closest_point_on_triangle(p, t[0], t[1], t[2]);
        if (q.distance * q.distance < best_sq) {
          best_sq = q.distance * q.distance;
          best.face = order_[i];
          best.bary = q.bary;
          best.point = q.point;
          best.distance = q.distance;
        }
      }
      continue;
    }
    const double dl = box_distance_sq(nodes_[node.left], p);
    const double dr = box_distance_sq(nodes_[node.right], p);
    // Push the farther child first so the nearer one is searched first.
    if (dl < dr) {
      stack.push_back(node.right);
      stack.push_back(node.left);
    } else {
      stack.push_back(node.left);
      stack.push_back(node.right);
    }
  }
  return best;
}

}  // namespace qs
