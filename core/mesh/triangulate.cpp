#include "core/mesh/triangulate.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

namespace qs {
namespace {

// A point in the polygon's plane.
struct Point2 {
  double x = 0.0;
  double y = 0.0;
};

// Twice the signed area of triangle (a, b, c): positive when it turns counter-clockwise.
double orient(const Point2& a, const Point2& b, const Point2& c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

// Orientation tests with a tolerance relative to the polygon's extent (largest |coordinate|
// in the plane): rounding on points that lie on one line, e.g. the straight sides of a CAD
// outline, must neither make an ear of three of them nor a crossing of two collinear edges.
// The tolerance is far above that rounding (~1e-16 * extent^2 for orient) and far below any
// real triangle (the mesh builder calls 1e-14 * diagonal^2 zero area).
class PlaneTests {
 public:
  explicit PlaneTests(double extent) : flat_(1e-12 * extent * extent), pad_(1e-12 * extent) {}

  int sign(const Point2& a, const Point2& b, const Point2& c) const {
    const double o = orient(a, b, c);
    return o > flat_ ? 1 : (o < -flat_ ? -1 : 0);
  }

  // True when the closed segments [a, b] and [c, d] have a point in common.
  bool segments_meet(const Point2& a, const Point2& b, const Point2& c, const Point2& d) const {
    const int d1 = sign(c, d, a);
    const int d2 = sign(c, d, b);
    const int d3 = sign(a, b, c);
    const int d4 = sign(a, b, d);
    if (d1 * d2 < 0 && d3 * d4 < 0) return true;
    return (d1 == 0 && in_box(a, c, d)) || (d2 == 0 && in_box(b, c, d)) ||
           (d3 == 0 && in_box(c, a, b)) || (d4 == 0 && in_box(d, a, b));
  }

  // True when the closed polygon q neither crosses nor touches itself: no two edges that do
  // not follow each other meet, and no edge doubles back over the previous one.
  bool is_simple(const std::vector<Point2>& q) const {
    const std::size_t n = q.size();
    for (std::size_t k = 0; k < n; ++k) {
      const Point2& a = q[(k + n - 1) % n];
      const Point2& b = q[k];
      const Point2& c = q[(k + 1) % n];
      const bool doubles_back =
          sign(a, b, c) == 0 && (a.x - b.x) * (c.x - b.x) + (a.y - b.y) * (c.y - b.y) > 0;
      if (doubles_back) return false;
    }
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = i + 2; j < n; ++j) {
        if (i == 0 && j == n - 1) continue;  // the last edge follows the first one
        if (segments_meet(q[i], q[i + 1], q[j], q[(j + 1) % n])) return false;
      }
    }
    return true;
  }

  // p inside or on the boundary of the counter-clockwise triangle (a, b, c), or within the
  // tolerance of it (so that an ear is never clipped over a corner).
  bool in_closed_triangle(const Point2& p, const Point2& a, const Point2& b,
                          const Point2& c) const {
    return sign(a, b, p) >= 0 && sign(b, c, p) >= 0 && sign(c, a, p) >= 0;
  }

 private:
  // p in the bounding box of [a, b], widened by the tolerance (p is collinear with them).
  bool in_box(const Point2& p, const Point2& a, const Point2& b) const {
    return std::min(a.x, b.x) - pad_ <= p.x && p.x <= std::max(a.x, b.x) + pad_ &&
           std::min(a.y, b.y) - pad_ <= p.y && p.y <= std::max(a.y, b.y) + pad_;
  }

  double flat_;  // largest |orient| counted as collinear
  double pad_;   // slack of the bounding-box test of collinear points
};

// Smallest corner angle of a triangle in radians.
double min_angle_rad(const Vec3& a, const Vec3& b, const Vec3& c) {
  const auto angle = [](const Vec3& apex, const Vec3& p, const Vec3& q) {
    const Vec3 u = p - apex;
    const Vec3 v = q - apex;
    // atan2 stays accurate for angles near 0 and pi, unlike acos of a normalized dot product.
    return std::atan2(OpenMesh::cross(u, v).norm(), OpenMesh::dot(u, v));
  };
  return std::min({angle(a, b, c), angle(b, c, a), angle(c, a, b)});
}

}  // namespace

Vec3 polygon_vector_area(std::span<const int> face, const std::vector<Vec3>& points) {
  Vec3 twice_area(0.0, 0.0, 0.0);
  const Vec3& origin = points[face[0]];
  for (std::size_t i = 1; i + 1 < face.size(); ++i) {
    twice_area += OpenMesh::cross(points[face[i]] - origin, points[face[i + 1]] - origin);
  }
  return 0.5 * twice_area;
}

std::vector<std::array<int, 3>> triangulate_polygon(std::span<const int> face,
                                                    const std::vector<Vec3>& points) {
  const std::size_t n = face.size();
  if (n < 3) return {};
  for (int v : face) {
    const Vec3& p = points[v];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) return {};
  }
  if (n == 3) return {{face[0], face[1], face[2]}};
  const Vec3 area = polygon_vector_area(face, points);
  const double norm = area.norm();
  if (!(norm > 0.0) || !std::isfinite(norm)) return {};

  // Plane axes u, v with u x v = the unit normal, so that counter-clockwise in the plane is
  // the polygon's own turning direction; centred for precision.
  const Vec3 normal = area / norm;
  int least = 0;
  for (int k = 1; k < 3; ++k) {
    if (std::abs(normal[k]) < std::abs(normal[least])) least = k;
  }
  Vec3 axis(0.0, 0.0, 0.0);
  axis[least] = 1.0;
  const Vec3 u = OpenMesh::cross(normal, axis).normalized();
  const Vec3 v = OpenMesh::cross(normal, u);
  Vec3 centre(0.0, 0.0, 0.0);
  for (int i : face) centre += points[i];
  centre /= static_cast<double>(n);
  std::vector<Point2> q(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 d = points[face[i]] - centre;
    q[i] = {OpenMesh::dot(d, u), OpenMesh::dot(d, v)};
  }
  double extent = 0.0;
  for (const Point2& p : q) extent = std::max({extent, std::abs(p.x), std::abs(p.y)});
  const PlaneTests plane(extent);
  if (!plane.is_simple(q)) return {};
  const auto corner = [&](std::size_t i) -> const Vec3& { return points[face[i]]; };

  // A fan from a corner that sees the whole polygon: every triangle turns counter-clockwise
  // (for a simple polygon their areas then sum to its area without overlap).
  std::size_t best_corner = n;
  double best_angle = -1.0;
  for (std::size_t c = 0; c < n; ++c) {
    double worst = std::numeric_limits<double>::infinity();
    for (std::size_t i = 1; i + 1 < n && worst > best_angle; ++i) {
      const std::size_t b = (c + i) % n;
      const std::size_t d = (c + i + 1) % n;
      worst = plane.sign(q[c], q[b], q[d]) > 0
                  ? std::min(worst, min_angle_rad(corner(c), corner(b), corner(d)))
                  : -1.0;
    }
    if (worst > best_angle) {
      best_angle = worst;
      best_corner = c;
    }
  }
  std::vector<std::array<int, 3>> triangles;
  triangles.reserve(n - 2);
  if (best_corner < n) {
    for (std::size_t i = 1; i + 1 < n; ++i) {
      triangles.push_back(
          {face[best_corner], face[(best_corner + i) % n], face[(best_corner + i + 1) % n]});
    }
    return triangles;
  }

  // Ear clipping: an ear is a convex corner whose triangle holds no other remaining corner.
  std::vector<std::size_t> prev(n);
  std::vector<std::size_t> next(n);
  for (std::size_t i = 0; i < n; ++i) {
    prev[i] = (i + n - 1) % n;
    next[i] = (i + 1) % n;
  }
  std::vector<char> removed(n, 0);
  std::vector<char> ear(n, 0);
  std::vector<double> quality(n, 0.0);
  const auto update = [&](std::size_t i) {
    const std::size_t a = prev[i];
    const std::size_t c = next[i];
    ear[i] = 0;
    if (plane.sign(q[a], q[i], q[c]) <= 0) return;
    for (std::size_t p = next[c]; p != a; p = next[p]) {
      if (plane.in_closed_triangle(q[p], q[a], q[i], q[c])) return;
    }
    ear[i] = 1;
    quality[i] = min_angle_rad(corner(a), corner(i), corner(c));
  };
  for (std::size_t i = 0; i < n; ++i) update(i);
  for (std::size_t remaining = n; remaining > 3; --remaining) {
    std::size_t best = n;
    for (std::size_t i = 0; i < n; ++i) {
      if (!removed[i] && ear[i] && (best == n || quality[i] > quality[best])) best = i;
    }
    if (best == n) return {};  // only possible through rounding on a nearly touching outline
    const std::size_t a = prev[best];
    const std::size_t c = next[best];
    triangles.push_back({face[a], face[best], face[c]});
    removed[best] = 1;
    next[a] = c;
    prev[c] = a;
    // The neighbours' triangles changed; any other corner may only have been blocked by the
    // clipped tip.
    for (std::size_t i = c; i != a; i = next[i]) {
      if (i == c || ear[i]) continue;
      if (plane.in_closed_triangle(q[best], q[prev[i]], q[i], q[next[i]])) update(i);
    }
    update(a);
    update(c);
  }
  std::size_t last = 0;
  while (removed[last]) ++last;
  // A flat last triangle is kept (the mesh builder reports it as zero area); an inverted one
  // means rounding trouble on a nearly touching outline.
  if (plane.sign(q[prev[last]], q[last], q[next[last]]) < 0) return {};
  triangles.push_back({face[prev[last]], face[last], face[next[last]]});
  return triangles;
}

}  // namespace qs
