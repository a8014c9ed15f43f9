#include "core/layout/symmetry.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>

#include "core/base/errors.h"

namespace qs {

namespace {

struct Box {
  Vec3 lo{0, 0, 0}, hi{0, 0, 0};
  double diagonal() const { return (hi - lo).norm(); }
};

Box bounding_box(const TriMesh& mesh) {
  Box box;
  bool first = true;
  for (const auto vh : mesh.vertices()) {
    const Vec3& p = mesh.point(vh);
    if (first) {
      box.lo = box.hi = p;
      first = false;
    } else {
      box.lo.minimize(p);
      box.hi.maximize(p);
    }
  }
  return box;
}

std::string fmt(double x) {
  std::ostringstream out;
  out.precision(3);
  out << x;
  return out.str();
}

// Vertex samples with their area weights (a third of the incident face areas).
struct Samples {
  std::vector<Vec3> points;
  std::vector<double> weights;
};

Samples vertex_samples(const TriMesh& mesh, int max_samples) {
  const int nv = int(mesh.n_vertices());
  std::vector<double> area(nv, 0.0);
  for (const auto fh : mesh.faces()) {
    auto it = mesh.cfv_begin(fh);
    const auto a = *it++, b = *it++, c = *it;
    const double A =
        0.5 * OpenMesh::cross(mesh.point(b) - mesh.point(a), mesh.point(c) - mesh.point(a)).norm();
    for (const auto vh : {a, b, c}) area[vh.idx()] += A / 3.0;
  }
  Samples s;
  const int stride = std::max(1, (nv + max_samples - 1) / max_samples);
  for (int v = 0; v < nv; v += stride) {
    if (!(area[v] > 0.0)) continue;
    s.points.push_back(mesh.point(OpenMesh::VertexHandle(v)));
    s.weights.push_back(area[v]);
  }
  return s;
}

// Distances of the reflected samples to the surface.
SymmetryFit residual(const Samples& s, const ClosestPointTree& tree, const MirrorPlane& plane,
                     double diagonal) {
  SymmetryFit fit;
  fit.plane = plane;
  double sum = 0.0, weight = 0.0;
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    const double d = tree.closest(plane.reflect(s.points[i])).distance;
    sum += s.weights[i] * d * d;
    weight += s.weights[i];
    fit.max = std::max(fit.max, d);
  }
  fit.rms = weight > 0.0 ? std::sqrt(sum / weight) : 0.0;
  fit.relative = diagonal > 0.0 ? fit.rms / diagonal : 0.0;
  return fit;
}

// Closest-point refinement of a plane from the correspondences of the samples p with the
// surface points q closest to their reflections. Bisector step: the normal along the dominant
// direction of p − q (the old normal's sign), the offset the mean of the midpoints along it;
// robust far from the solution, but slow where the surface is flat (the pairs slide).
// Point-to-plane step (Gauss-Newton): the plane change that best moves the reflections onto the
// tangent planes at q; fast near the solution.
class PlaneRefiner {
 public:
  PlaneRefiner(const TriMesh& mesh, const ClosestPointTree& tree, const Samples& s, double diagonal)
      : tree_(tree), s_(s), diagonal_(diagonal), normals_(mesh.n_faces()) {
    for (const auto fh : mesh.faces()) {
      auto it = mesh.cfv_begin(fh);
      const Vec3 a = mesh.point(*it++), b = mesh.point(*it++), c = mesh.point(*it);
      Vec3 n = OpenMesh::cross(b - a, c - a);
      const double len = n.norm();
      normals_[fh.idx()] = len > 0.0 ? n / len : Vec3(0, 0, 0);
    }
  }

  MirrorPlane refine(MirrorPlane plane, int iterations) const {
    int it = 0;
    for (; it < (iterations + 1) / 2; ++it) {
      const MirrorPlane next = bisector_step(plane);
      const bool converged = small_change(plane, next);
      plane = next;
      if (converged) break;
    }
    const MirrorPlane coarse = plane;
    for (; it < iterations; ++it) {
      const MirrorPlane next = point_to_plane_step(plane);
      const bool converged = small_change(plane, next);
      plane = next;
      if (converged) break;
    }
    if (iterations == 0 || (coarse.normal == plane.normal && coarse.offset == plane.offset))
      return plane;
    // Keep the fine steps only when they helped (they can stray from a poor start).
    return residual(s_, tree_, plane, diagonal_).rms <= residual(s_, tree_, coarse, diagonal_).rms
               ? plane
               : coarse;
  }

 private:
  bool small_change(const MirrorPlane& a, const MirrorPlane& b) const {
    return (a.normal - b.normal).norm() < 1e-13 &&
           std::abs(a.offset - b.offset) < 1e-13 * diagonal_;
  }

  MirrorPlane bisector_step(const MirrorPlane& plane) const {
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    std::vector<Vec3> midpoints(s_.points.size());
    for (std::size_t i = 0; i < s_.points.size(); ++i) {
      const Vec3 q = tree_.closest(plane.reflect(s_.points[i])).point;
      const Vec3 d = s_.points[i] - q;
      const Eigen::Vector3d e(d[0], d[1], d[2]);
      scatter += s_.weights[i] * e * e.transpose();
      midpoints[i] = 0.5 * (s_.points[i] + q);
    }
    if (!(scatter.trace() > 0.0)) return plane;  // every sample on the plane already
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);
    const Eigen::Vector3d v = eig.eigenvectors().col(2);
    Vec3 n(v[0], v[1], v[2]);
    if (OpenMesh::dot(n, plane.normal) < 0.0) n = -n;
    n.normalize();
    double sum = 0.0, weight = 0.0;
    for (std::size_t i = 0; i < s_.points.size(); ++i) {
      sum += s_.weights[i] * OpenMesh::dot(n, midpoints[i]);
      weight += s_.weights[i];
    }
    return MirrorPlane{n, weight > 0.0 ? sum / weight : plane.offset};
  }

  MirrorPlane point_to_plane_step(const MirrorPlane& plane) const {
    const Vec3& n = plane.normal;
    // Tangent basis of the normal's changes.
    Vec3 t1 = std::abs(n[0]) < 0.9 ? OpenMesh::cross(n, Vec3(1, 0, 0))
                                   : OpenMesh::cross(n, Vec3(0, 1, 0));
    t1.normalize();
    const Vec3 t2 = OpenMesh::cross(n, t1);
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < s_.points.size(); ++i) {
      const Vec3& p = s_.points[i];
      const Vec3 r = plane.reflect(p);
      const ClosestPoint hit = tree_.closest(r);
      const Vec3& m = normals_[hit.face];
      const double h = plane.signed_distance(p);
      // d R / d(a, b, offset) for n -> n + a t1 + b t2, offset -> offset + c.
      const Vec3 da = -2.0 * (OpenMesh::dot(t1, p) * n + h * t1);
      const Vec3 db = -2.0 * (OpenMesh::dot(t2, p) * n + h * t2);
      const Vec3 dc = 2.0 * n;
      const Eigen::Vector3d J(OpenMesh::dot(m, da), OpenMesh::dot(m, db), OpenMesh::dot(m, dc));
      const double res = OpenMesh::dot(m, r - hit.point);
      A += s_.weights[i] * J * J.transpose();
      b -= s_.weights[i] * res * J;
    }
    A += 1e-12 * (A.trace() + 1e-300) * Eigen::Matrix3d::Identity();
    const Eigen::Vector3d x = A.ldlt().solve(b);
    if (!x.allFinite()) return plane;
    Vec3 next = n + x[0] * t1 + x[1] * t2;
    next.normalize();
    return MirrorPlane{next, plane.offset + x[2]};
  }

  const ClosestPointTree& tree_;
  const Samples& s_;
  double diagonal_;
  std::vector<Vec3> normals_;
};

Vec3 node_position(const TriMesh& mesh, const LayoutNode& node) {
  if (node.vertex >= 0 && node.vertex < int(mesh.n_vertices()))
    return mesh.point(OpenMesh::VertexHandle(node.vertex));
  if (node.point) return surface_point_position(mesh, *node.point);
  throw InvalidInputError("node " + std::to_string(node.id) + " has no valid vertex or point");
}

double distance_to_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = ab.sqrnorm();
  const double t = len2 > 0.0 ? std::clamp(OpenMesh::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

std::vector<Vec3> arc_points(const TriMesh& mesh, const LayoutArc& arc) {
  std::vector<Vec3> out;
  for (int v : arc.path)
    if (v >= 0 && v < int(mesh.n_vertices())) out.push_back(mesh.point(OpenMesh::VertexHandle(v)));
  if (out.empty())
    for (const auto& p : arc.points) out.push_back(surface_point_position(mesh, p));
  return out;
}

// Largest distance of a's reflected points from b's polyline (infinity when either is empty).
double arc_deviation(const std::vector<Vec3>& a, const std::vector<Vec3>& b,
                     const MirrorPlane& plane) {
  if (a.empty() || b.empty()) return std::numeric_limits<double>::infinity();
  double worst = 0.0;
  for (const Vec3& p : a) {
    const Vec3 r = plane.reflect(p);
    double best = (r - b[0]).norm();
    for (std::size_t k = 0; k + 1 < b.size(); ++k)
      best = std::min(best, distance_to_segment(r, b[k], b[k + 1]));
    worst = std::max(worst, best);
  }
  return worst;
}

// Vertices near the closest point of \p x: the face's corners and their neighbours.
std::vector<int> candidates_near(const TriMesh& mesh, const ClosestPoint& hit) {
  std::vector<int> out;
  if (hit.face < 0) return out;
  for (const auto vh : mesh.fv_range(OpenMesh::FaceHandle(hit.face))) {
    out.push_back(vh.idx());
    for (const auto wh : mesh.vv_range(vh)) out.push_back(wh.idx());
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

// The point of the curve where the plane cuts the surface that is nearest to \p y, searched in
// the faces within a few rings of the face closest to y (the closest surface point itself
// when it lies on the plane, or when the plane cuts none of those faces).
ProjectedPoint closest_on_plane_curve(const TriMesh& mesh, const ClosestPointTree& tree,
                                      const MirrorPlane& plane, const Vec3& y, double diagonal) {
  const ClosestPoint hit = tree.closest(y);
  ProjectedPoint best;
  best.point.face = hit.face;
  best.point.bary = hit.bary;
  best.position = hit.point;
  best.distance = hit.distance;
  if (hit.face < 0 || std::abs(plane.signed_distance(hit.point)) <= 1e-13 * diagonal) return best;
  double best_d = std::numeric_limits<double>::infinity();
  std::vector<int> ring{hit.face};
  std::vector<char> seen(mesh.n_faces(), 0);
  seen[hit.face] = 1;
  constexpr int kRings = 4;
  for (int r = 0; r <= kRings && !ring.empty(); ++r) {
    std::vector<int> next;
    for (int f : ring) {
      const OpenMesh::FaceHandle fh(f);
      std::array<Vec3, 3> x;
      std::array<double, 3> sd;
      int k = 0;
      for (const auto vh : mesh.fv_range(fh)) {
        x[k] = mesh.point(vh);
        sd[k] = plane.signed_distance(x[k]);
        ++k;
      }
      // Points of the face's edges on the plane, as barycentrics.
      std::vector<std::array<double, 3>> cut;
      for (int e = 0; e < 3; ++e) {
        const int a = e, b = (e + 1) % 3;
        if (sd[a] == 0.0) {
          std::array<double, 3> w{0, 0, 0};
          w[a] = 1.0;
          cut.push_back(w);
        } else if ((sd[a] < 0.0) != (sd[b] < 0.0) && sd[b] != 0.0) {
          const double t = sd[a] / (sd[a] - sd[b]);
          std::array<double, 3> w{0, 0, 0};
          w[a] = 1.0 - t;
          w[b] = t;
          cut.push_back(w);
        }
      }
      if (!cut.empty()) {
        const auto pos = [&](const std::array<double, 3>& w) {
          return w[0] * x[0] + w[1] * x[1] + w[2] * x[2];
        };
        const Vec3 a = pos(cut.front()), b = pos(cut.back());
        const Vec3 ab = b - a;
        const double len2 = ab.sqrnorm();
        const double t = len2 > 0.0 ? std::clamp(OpenMesh::dot(y - a, ab) / len2, 0.0, 1.0) : 0.0;
        const Vec3 p = a + t * ab;
        const double d = (p - y).norm();
        if (d < best_d) {
          best_d = d;
          best.point.face = f;
          for (int c = 0; c < 3; ++c)
            best.point.bary[c] = (1.0 - t) * cut.front()[c] + t * cut.back()[c];
          best.position = p;
          best.distance = d;
        }
      }
      for (const auto gh : mesh.ff_range(fh))
        if (!seen[gh.idx()]) {
          seen[gh.idx()] = 1;
          next.push_back(gh.idx());
        }
    }
    ring = std::move(next);
  }
  return best;
}

}  // namespace

std::string describe_plane(const MirrorPlane& plane) {
  std::ostringstream out;
  out.precision(6);
  out << "normal (" << plane.normal[0] << ", " << plane.normal[1] << ", " << plane.normal[2]
      << "), offset " << plane.offset;
  return out.str();
}

const char* to_string(SymmetryAxis axis) {
  switch (axis) {
    case SymmetryAxis::X:
      return "x";
    case SymmetryAxis::Y:
      return "y";
    case SymmetryAxis::Z:
      return "z";
    case SymmetryAxis::Auto:
      return "auto";
  }
  return "?";
}

SymmetryAxis parse_symmetry_axis(const std::string& name) {
  for (SymmetryAxis a : {SymmetryAxis::X, SymmetryAxis::Y, SymmetryAxis::Z, SymmetryAxis::Auto})
    if (name == to_string(a)) return a;
  throw InvalidInputError("unknown symmetry axis '" + name + "': expected x, y, z or auto");
}

void validate_symmetry_fit_options(const SymmetryFitOptions& options) {
  if (options.max_samples < 16)
    throw InvalidInputError("symmetry max_samples must be at least 16, got " +
                            std::to_string(options.max_samples));
  if (options.iterations < 0 || options.iterations > 1000)
    throw InvalidInputError("symmetry iterations must be in [0, 1000], got " +
                            std::to_string(options.iterations));
}

MirrorPlane axis_plane(const TriMesh& mesh, int axis) {
  if (axis < 0 || axis > 2) throw InvalidInputError("axis must be 0 (x), 1 (y) or 2 (z)");
  if (mesh.n_vertices() == 0) throw InvalidInputError("the mesh has no vertices");
  const Box box = bounding_box(mesh);
  MirrorPlane plane;
  plane.normal = Vec3(0, 0, 0);
  plane.normal[axis] = 1.0;
  plane.offset = 0.5 * (box.lo[axis] + box.hi[axis]);
  return plane;
}

SymmetryFit measure_symmetry(const TriMesh& mesh, const ClosestPointTree& tree,
                             const MirrorPlane& plane, const SymmetryFitOptions& options) {
  validate_symmetry_fit_options(options);
  return residual(vertex_samples(mesh, options.max_samples), tree, plane,
                  bounding_box(mesh).diagonal());
}

SymmetryFit fit_mirror_plane(const TriMesh& mesh, const ClosestPointTree& tree,
                             const SymmetryFitOptions& options) {
  validate_symmetry_fit_options(options);
  if (mesh.n_faces() == 0) throw InvalidInputError("the mesh has no faces");
  const double diagonal = bounding_box(mesh).diagonal();
  const Samples s = vertex_samples(mesh, options.max_samples);
  double weight = 0.0;
  Vec3 centroid(0, 0, 0);
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    centroid += s.weights[i] * s.points[i];
    weight += s.weights[i];
  }
  if (!(weight > 0.0)) throw InvalidInputError("the mesh has no area");
  centroid /= weight;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    const Vec3 d = s.points[i] - centroid;
    const Eigen::Vector3d e(d[0], d[1], d[2]);
    cov += s.weights[i] * e * e.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  std::vector<Vec3> normals;
  for (int k = 2; k >= 0; --k) {
    const Eigen::Vector3d v = eig.eigenvectors().col(k);
    normals.emplace_back(v[0], v[1], v[2]);
  }
  normals.emplace_back(1, 0, 0);
  normals.emplace_back(0, 1, 0);
  normals.emplace_back(0, 0, 1);
  // Coarse round: every candidate on a quarter of the samples with a third of the iterations;
  // the two best are refined on all samples.
  Samples coarse;
  for (std::size_t i = 0; i < s.points.size(); i += 4) {
    coarse.points.push_back(s.points[i]);
    coarse.weights.push_back(s.weights[i]);
  }
  const PlaneRefiner coarse_refiner(mesh, tree, coarse, diagonal);
  std::vector<SymmetryFit> rough;
  std::vector<Vec3> tried;
  for (Vec3 n : normals) {
    n.normalize();
    // A coordinate axis that equals a principal axis is tried once.
    if (std::any_of(tried.begin(), tried.end(),
                    [&](const Vec3& t) { return std::abs(OpenMesh::dot(t, n)) > 1.0 - 1e-9; }))
      continue;
    tried.push_back(n);
    const MirrorPlane plane = coarse_refiner.refine(MirrorPlane{n, OpenMesh::dot(n, centroid)},
                                                    (options.iterations + 2) / 3);
    rough.push_back(residual(coarse, tree, plane, diagonal));
  }
  std::stable_sort(rough.begin(), rough.end(),
                   [](const SymmetryFit& a, const SymmetryFit& b) { return a.rms < b.rms; });
  const PlaneRefiner refiner(mesh, tree, s, diagonal);
  SymmetryFit best;
  for (std::size_t k = 0; k < std::min<std::size_t>(2, rough.size()); ++k) {
    const SymmetryFit fit =
        residual(s, tree, refiner.refine(rough[k].plane, options.iterations), diagonal);
    if (k == 0 || fit.rms < best.rms) best = fit;
  }
  return best;
}

SymmetryFit mirror_plane(const TriMesh& mesh, const ClosestPointTree& tree, SymmetryAxis axis,
                         const SymmetryFitOptions& options) {
  if (axis == SymmetryAxis::Auto) return fit_mirror_plane(mesh, tree, options);
  return measure_symmetry(mesh, tree, axis_plane(mesh, int(axis)), options);
}

Vec3 surface_point_position(const TriMesh& mesh, const SurfacePoint& p) {
  if (p.face < 0 || p.face >= int(mesh.n_faces()))
    throw InvalidInputError("surface point face " + std::to_string(p.face) + " out of range");
  Vec3 x(0, 0, 0);
  int k = 0;
  for (const auto vh : mesh.fv_range(OpenMesh::FaceHandle(p.face)))
    if (k < 3) x += p.bary[k++] * mesh.point(vh);
  return x;
}

ProjectedPoint project_to_surface(const ClosestPointTree& tree, const Vec3& x) {
  const ClosestPoint hit = tree.closest(x);
  ProjectedPoint out;
  out.point.face = hit.face;
  out.point.bary = hit.bary;
  out.position = hit.point;
  out.distance = hit.distance;
  return out;
}

ProjectedPoint reflect_surface_point(const TriMesh& mesh, const ClosestPointTree& tree,
                                     const MirrorPlane& plane, const SurfacePoint& p) {
  return project_to_surface(tree, plane.reflect(surface_point_position(mesh, p)));
}

int mirror_vertex(const TriMesh& mesh, const ClosestPointTree& tree, const MirrorPlane& plane,
                  int v) {
  if (v < 0 || v >= int(mesh.n_vertices()))
    throw InvalidInputError("vertex " + std::to_string(v) + " out of range");
  const Vec3 target = plane.reflect(mesh.point(OpenMesh::VertexHandle(v)));
  int best = -1;
  double best_d = std::numeric_limits<double>::infinity();
  for (int w : candidates_near(mesh, tree.closest(target))) {
    const double d = (mesh.point(OpenMesh::VertexHandle(w)) - target).sqrnorm();
    if (d < best_d) {
      best_d = d;
      best = w;
    }
  }
  return best;
}

int plane_vertex(const TriMesh& mesh, const ClosestPointTree& tree, const MirrorPlane& plane,
                 const Vec3& x) {
  const Vec3 y = plane.project(x);
  const double tie = 1e-9 * bounding_box(mesh).diagonal();
  int best = -1;
  double best_plane = std::numeric_limits<double>::infinity();
  double best_d = std::numeric_limits<double>::infinity();
  for (int w : candidates_near(mesh, tree.closest(y))) {
    const Vec3& p = mesh.point(OpenMesh::VertexHandle(w));
    const double off = std::abs(plane.signed_distance(p));
    const double d = (p - y).norm();
    if (off < best_plane - tie || (off <= best_plane + tie && d < best_d)) {
      best_plane = std::min(off, best_plane);
      best_d = d;
      best = w;
    }
  }
  return best;
}

std::vector<int> mirror_path(const TriMesh& mesh, const ClosestPointTree& tree,
                             const MirrorPlane& plane, const std::vector<int>& path,
                             const RoutingObstacles& obstacles, int first, int last) {
  std::vector<int> mirrored;
  for (std::size_t k = 0; k < path.size(); ++k) {
    int m = mirror_vertex(mesh, tree, plane, path[k]);
    if (k == 0 && first >= 0) m = first;
    if (k + 1 == path.size() && last >= 0) m = last;
    if (mirrored.empty() || mirrored.back() != m) mirrored.push_back(m);
  }
  if (mirrored.size() < 2) return mirrored;
  RoutingObstacles blocked = obstacles;
  std::vector<int> out{mirrored[0]};
  for (std::size_t k = 0; k + 1 < mirrored.size(); ++k) {
    const int a = mirrored[k], b = mirrored[k + 1];
    // The path's own vertices so far are obstacles for its next pieces (never revisited).
    for (int v : out) blocked.vertex_blocked[v] = 1;
    if (k + 2 < mirrored.size() && blocked.vertex_blocked[b]) return {};
    std::vector<int> piece;
    bool adjacent = false;
    for (const auto heh : mesh.voh_range(OpenMesh::VertexHandle(a)))
      if (mesh.to_vertex_handle(heh).idx() == b) {
        adjacent = !blocked.edge_blocked[mesh.edge_handle(heh).idx()];
        break;
      }
    piece = adjacent ? std::vector<int>{a, b} : shortest_path(mesh, a, b, blocked);
    if (piece.size() < 2) return {};
    out.insert(out.end(), piece.begin() + 1, piece.end());
  }
  return out;
}

SymmetryPairs match_mirror_pairs(const TriMesh& mesh, const Layout& layout,
                                 const MirrorPlane& plane, const SymmetryPairOptions& options) {
  if (!(options.tolerance > 0.0 && options.tolerance <= 1.0))
    throw InvalidInputError("symmetry tolerance must be in (0, 1], got " + fmt(options.tolerance));
  if (!(options.edge_lengths >= 0.0) || !std::isfinite(options.edge_lengths))
    throw InvalidInputError("symmetry edge_lengths must be a finite number >= 0, got " +
                            fmt(options.edge_lengths));
  const double diagonal = std::max(bounding_box(mesh).diagonal(), 1e-300);
  double mean_edge = 0.0;
  if (options.edge_lengths > 0.0 && mesh.n_edges() > 0) {
    for (const auto eh : mesh.edges()) mean_edge += mesh.calc_edge_length(eh);
    mean_edge /= double(mesh.n_edges());
  }
  const double tol = std::max(options.tolerance * diagonal, options.edge_lengths * mean_edge);
  const int nn = int(layout.nodes.size());
  const int na = int(layout.arcs.size());
  SymmetryPairs pairs;
  pairs.node_mirror.assign(nn, -1);
  pairs.arc_mirror.assign(na, -1);

  std::vector<Vec3> x(nn);
  for (int i = 0; i < nn; ++i) x[i] = node_position(mesh, layout.nodes[i]);
  // Nearest node to each node's reflection (O(#nodes²): layouts have few nodes).
  std::vector<int> nearest(nn, -1);
  std::vector<double> nearest_d(nn, std::numeric_limits<double>::infinity());
  for (int i = 0; i < nn; ++i) {
    const Vec3 r = plane.reflect(x[i]);
    for (int j = 0; j < nn; ++j) {
      const double d = (x[j] - r).norm();
      if (d < nearest_d[i]) {
        nearest_d[i] = d;
        nearest[i] = j;
      }
    }
  }
  for (int i = 0; i < nn; ++i) {
    const int j = nearest[i];
    if (j < 0 || nearest_d[i] > tol || nearest[j] != i) {
      if (pairs.first_unpaired_node < 0) {
        pairs.first_unpaired_node = i;
        const LayoutNode& node = layout.nodes[i];
        std::string why = "node " + std::to_string(node.id) + " (vertex " +
                          std::to_string(node.vertex) + ") has no mirror node within " +
                          fmt(tol / diagonal) + " of the bounding-box diagonal";
        if (j >= 0 && nearest_d[i] > tol)
          why += " (the nearest to its mirror image, node " + std::to_string(layout.nodes[j].id) +
                 ", is " + fmt(nearest_d[i] / diagonal) + " of the diagonal away)";
        else if (j >= 0)
          why += " (its mirror image is nearest to node " + std::to_string(layout.nodes[j].id) +
                 ", which pairs with another node)";
        pairs.problem = why;
      }
      continue;
    }
    pairs.node_mirror[i] = j;
    pairs.node_error = std::max(pairs.node_error, nearest_d[i] / diagonal);
  }

  // Arcs: the candidates join the mirrors of the arc's ends (either direction); the one whose
  // polyline follows the reflection best.
  std::vector<std::vector<Vec3>> points(na);
  for (int a = 0; a < na; ++a) points[a] = arc_points(mesh, layout.arcs[a]);
  std::map<std::pair<int, int>, std::vector<int>> by_ends;  // (min, max) node index; -1 dangling
  auto end_index = [&](int id) { return id < 0 ? -1 : layout.node_index(id); };
  auto key = [](int u, int v) { return std::make_pair(std::min(u, v), std::max(u, v)); };
  for (int a = 0; a < na; ++a) {
    const LayoutArc& arc = layout.arcs[a];
    by_ends[key(end_index(arc.from), end_index(arc.to))].push_back(a);
  }
  std::vector<double> deviation(na, std::numeric_limits<double>::infinity());
  std::string arc_problem;
  for (int a = 0; a < na; ++a) {
    const LayoutArc& arc = layout.arcs[a];
    const int u = end_index(arc.from), v = end_index(arc.to);
    const int mu = u >= 0 ? pairs.node_mirror[u] : -1;
    const int mv = v >= 0 ? pairs.node_mirror[v] : -1;
    std::string why;
    if (u < 0 || mu < 0 || (v >= 0 && mv < 0)) {
      why = "its end nodes have no mirror nodes";
    } else {
      const auto it = by_ends.find(key(mu, v >= 0 ? mv : -1));
      int best = -1;
      double best_d = std::numeric_limits<double>::infinity();
      if (it != by_ends.end())
        for (int b : it->second) {
          if (v < 0 && end_index(layout.arcs[b].from) != mu) continue;  // dangling: same start
          const double d = arc_deviation(points[a], points[b], plane);
          if (d < best_d) {
            best_d = d;
            best = b;
          }
        }
      if (best < 0) {
        why = "no arc joins the mirror nodes";
      } else if (best_d > tol) {
        why = "the arc " + std::to_string(layout.arcs[best].id) +
              " that joins the mirror nodes is " + fmt(best_d / diagonal) +
              " of the diagonal away from its mirror image";
      } else {
        pairs.arc_mirror[a] = best;
        deviation[a] = best_d;
      }
    }
    if (!why.empty() && arc_problem.empty()) {
      pairs.first_unpaired_arc = a;
      arc_problem = "arc " + std::to_string(arc.id) + " (nodes " + std::to_string(arc.from) +
                    " to " + (arc.to < 0 ? std::string("the boundary") : std::to_string(arc.to)) +
                    ") has no mirror arc: " + why;
    }
  }
  // Mutual: two arcs claiming the same mirror leave the worse one unpaired.
  for (int a = 0; a < na; ++a) {
    const int b = pairs.arc_mirror[a];
    if (b < 0) continue;
    if (pairs.arc_mirror[b] != a) {
      pairs.arc_mirror[a] = -1;
      if (pairs.first_unpaired_arc < 0 || a < pairs.first_unpaired_arc) {
        pairs.first_unpaired_arc = a;
        arc_problem = "arc " + std::to_string(layout.arcs[a].id) +
                      " has no mirror arc: its mirror "
                      "image is nearest to arc " +
                      std::to_string(layout.arcs[b].id) + ", which pairs with another arc";
      }
    }
  }
  for (int a = 0; a < na; ++a)
    if (pairs.arc_mirror[a] >= 0)
      pairs.arc_error = std::max(pairs.arc_error, deviation[a] / diagonal);
  if (pairs.problem.empty()) pairs.problem = arc_problem;
  return pairs;
}

SymmetryPairs find_mirror_pairs(const TriMesh& mesh, const Layout& layout, const MirrorPlane& plane,
                                const SymmetryPairOptions& options) {
  SymmetryPairs pairs = match_mirror_pairs(mesh, layout, plane, options);
  if (!pairs.symmetric())
    throw InvalidInputError("the layout is not mirror symmetric about the plane (" +
                            describe_plane(plane) + "): " + pairs.problem);
  return pairs;
}

std::vector<SurfacePoint> symmetrize_targets(const TriMesh& mesh, const ClosestPointTree& tree,
                                             const MirrorPlane& plane,
                                             const std::vector<int>& node_mirror,
                                             const std::vector<SurfacePoint>& targets,
                                             const std::vector<char>& fixed) {
  const int n = int(targets.size());
  if (int(node_mirror.size()) != n)
    throw InvalidInputError("symmetrize_targets: " + std::to_string(node_mirror.size()) +
                            " mirror indices for " + std::to_string(n) + " targets");
  if (!fixed.empty() && int(fixed.size()) != n)
    throw InvalidInputError("symmetrize_targets: " + std::to_string(fixed.size()) +
                            " fixed flags for " + std::to_string(n) + " targets");
  for (int i = 0; i < n; ++i) {
    const int j = node_mirror[i];
    if (j < -1 || j >= n)
      throw InvalidInputError("symmetrize_targets: node index " + std::to_string(i) +
                              " has mirror " + std::to_string(j) + " out of range");
    if (j >= 0 && node_mirror[j] != i)
      throw InvalidInputError("symmetrize_targets: node index " + std::to_string(i) +
                              " pairs with " + std::to_string(j) + ", which pairs with " +
                              std::to_string(node_mirror[j]));
  }
  auto is_fixed = [&](int i) { return !fixed.empty() && fixed[i]; };
  const double diagonal = bounding_box(mesh).diagonal();
  // The mirror image of a surface point: exact (the reflection lies on the surface) on a mesh
  // with a symmetric tessellation, so a pair never takes two different closest points.
  auto mirrored = [&](const SurfacePoint& p) {
    return project_to_surface(tree, plane.reflect(surface_point_position(mesh, p))).point;
  };
  std::vector<SurfacePoint> out = targets;
  for (int i = 0; i < n; ++i) {
    const int j = node_mirror[i];
    if (j < 0 || j < i) continue;  // unpaired, or done with its partner
    const Vec3 xi = surface_point_position(mesh, targets[i]);
    if (j == i) {
      // Onto the plane, then onto the surface along the plane: from inside a faceted surface the
      // closest point can be either of two mirror images off the plane.
      if (!is_fixed(i))
        out[i] = closest_on_plane_curve(mesh, tree, plane, plane.project(xi), diagonal).point;
      continue;
    }
    if (is_fixed(i) && is_fixed(j)) continue;
    if (is_fixed(i)) {
      out[j] = mirrored(targets[i]);
    } else if (is_fixed(j)) {
      out[i] = mirrored(targets[j]);
    } else {
      const Vec3 xj = surface_point_position(mesh, targets[j]);
      out[i] = project_to_surface(tree, 0.5 * (xi + plane.reflect(xj))).point;
      out[j] = mirrored(out[i]);
    }
  }
  return out;
}

}  // namespace qs
