#include "core/param/sizing.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "core/base/errors.h"
#include "core/field/topology.h"

namespace qs {

namespace {

using Vec2 = Eigen::Vector2d;

void check_sizes(const GeometryCache& g, const std::vector<double>& theta,
                 const std::vector<int>& period_jump, const std::vector<double>& log_scale) {
  if (static_cast<int>(theta.size()) != g.n_faces)
    throw InvalidInputError("sizing: the field has " + std::to_string(theta.size()) +
                            " angles for " + std::to_string(g.n_faces) + " faces");
  if (static_cast<int>(period_jump.size()) != g.n_edges)
    throw InvalidInputError("sizing: " + std::to_string(period_jump.size()) + " period jumps for " +
                            std::to_string(g.n_edges) + " edges");
  if (!log_scale.empty() && static_cast<int>(log_scale.size()) != g.n_faces)
    throw InvalidInputError("sizing: " + std::to_string(log_scale.size()) + " log-scales for " +
                            std::to_string(g.n_faces) + " faces");
}

// Edge of the side from corner k to corner k + 1 of every face.
std::vector<std::array<int, 3>> face_edges(const TriMesh& mesh, const GeometryCache& g) {
  std::vector<std::array<int, 3>> out(g.n_faces);
  for (int f = 0; f < g.n_faces; ++f) {
    const auto& fv = g.face_vertices[f];
    for (int k = 0; k < 3; ++k) {
      const auto h =
          mesh.find_halfedge(mesh.vertex_handle(fv[k]), mesh.vertex_handle(fv[(k + 1) % 3]));
      out[f][k] = mesh.edge_handle(h).idx();
    }
  }
  return out;
}

// Corners of face f in its 2D frame and twice its signed area.
double corners_2d(const TriMesh& mesh, const GeometryCache& g, int f, Vec2 p[3]) {
  const auto c = face_corners_2d(mesh, g, f);
  for (int k = 0; k < 3; ++k) p[k] = Vec2(c[k][0], c[k][1]);
  const Vec2 a = p[1] - p[0], b = p[2] - p[0];
  return a.x() * b.y() - a.y() * b.x();
}

// Discrete curls of e^s û and e^s v̂ in face f (header: (1/A) Σ ½ [w]·e = Σ [w]·e / 2A; at the
// boundary over the area share of the interior edges).
void face_curl(const GeometryCache& g, const Vec2 p[3], double a2, int f,
               const std::array<int, 3>& edges, const std::vector<double>& theta,
               const std::vector<int>& period_jump, const std::vector<double>& log_scale,
               double& curl_u, double& curl_v) {
  curl_u = curl_v = 0;
  if (!(a2 > 0)) return;
  const double th = theta[f];
  const double sf = log_scale.empty() ? 1.0 : std::exp(log_scale[f]);
  const Vec2 u = sf * Vec2(std::cos(th), std::sin(th));
  const Vec2 v(-u.y(), u.x());
  double su = 0, sv = 0;
  int interior = 0;
  for (int k = 0; k < 3; ++k) {
    const int e = edges[k];
    const int i = g.edge_face_i[e], j = g.edge_face_j[e];
    if (i < 0 || j < 0) continue;  // boundary: no jump
    ++interior;
    const int other = i == f ? j : i;
    double delta = theta[j] - theta[i] - g.kappa[e] - 0.5 * M_PI * period_jump[e];
    if (f == j) delta = -delta;
    const double so = log_scale.empty() ? 1.0 : std::exp(log_scale[other]);
    const Vec2 u2 = so * Vec2(std::cos(th + delta), std::sin(th + delta));
    const Vec2 v2(-u2.y(), u2.x());
    const Vec2 edge = p[(k + 1) % 3] - p[k];
    su += (u2 - u).dot(edge);
    sv += (v2 - v).dot(edge);
  }
  if (interior == 0) return;
  // Each interior edge accounts for a third of the face: at the boundary the circulation of
  // the interior edges is spread over their share of the area only (no bias toward 0 there).
  curl_u = 3.0 * su / (interior * a2);
  curl_v = 3.0 * sv / (interior * a2);
}

}  // namespace

FieldCurl field_curl(const TriMesh& mesh, const GeometryCache& g, const std::vector<double>& theta,
                     const std::vector<int>& period_jump, const std::vector<double>& log_scale) {
  check_sizes(g, theta, period_jump, log_scale);
  const auto edges = face_edges(mesh, g);
  FieldCurl out;
  out.u.assign(g.n_faces, 0.0);
  out.v.assign(g.n_faces, 0.0);
  for (int f = 0; f < g.n_faces; ++f) {
    Vec2 p[3];
    const double a2 = corners_2d(mesh, g, f, p);
    face_curl(g, p, a2, f, edges[f], theta, period_jump, log_scale, out.u[f], out.v[f]);
  }
  return out;
}

SizingSolver::SizingSolver(const TriMesh& mesh, const GeometryCache& g,
                           const SizingOptions& options)
    : options_(options) {
  if (!std::isfinite(options_.clamp) || options_.clamp < 0)
    throw InvalidInputError("sizing: clamp must be a finite number ≥ 0, got " +
                            std::to_string(options_.clamp));
  face_vertices_ = g.face_vertices;
  face_edges_ = face_edges(mesh, g);
  // Connected components (union–find over face corners); the first vertex of each is pinned.
  std::vector<int> parent(g.n_vertices);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (const auto& fv : g.face_vertices)
    for (int k = 1; k < 3; ++k) parent[find(fv[k])] = find(fv[0]);
  component_.assign(g.n_vertices, -1);
  free_index_.assign(g.n_vertices, -1);
  std::vector<int> root_component(g.n_vertices, -1);
  int free = 0;
  for (int v = 0; v < g.n_vertices; ++v) {
    const int r = find(v);
    if (root_component[r] < 0) {
      root_component[r] = components_++;
      component_[v] = root_component[r];
      continue;  // pinned
    }
    component_[v] = root_component[r];
    free_index_[v] = free++;
  }
  // Pattern of the reduced Laplacian (lower triangle, with every diagonal entry).
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(6 * g.n_faces + free);
  for (int i = 0; i < free; ++i) trip.emplace_back(i, i, 0.0);
  for (const auto& fv : g.face_vertices)
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l) {
        const int a = free_index_[fv[k]], b = free_index_[fv[l]];
        if (a >= 0 && b >= 0 && a > b) trip.emplace_back(a, b, 0.0);
      }
  L_.resize(free, free);
  L_.setFromTriplets(trip.begin(), trip.end());
  L_.makeCompressed();
  gradient_.resize(g.n_faces);
  area_.assign(g.n_faces, 0.0);
}

SizingSolver::~SizingSolver() = default;
SizingSolver::SizingSolver(SizingSolver&&) noexcept = default;
SizingSolver& SizingSolver::operator=(SizingSolver&&) noexcept = default;

bool SizingSolver::same_connectivity(const GeometryCache& g) const {
  return g.face_vertices == face_vertices_ && static_cast<int>(free_index_.size()) == g.n_vertices;
}

void SizingSolver::assemble(const TriMesh& mesh, const GeometryCache& g) {
  std::fill(L_.valuePtr(), L_.valuePtr() + L_.nonZeros(), 0.0);
  auto slot = [&](int row, int col) -> double& {  // row ≥ col, both free
    const int* begin = L_.innerIndexPtr() + L_.outerIndexPtr()[col];
    const int* end = L_.innerIndexPtr() + L_.outerIndexPtr()[col + 1];
    const int* it = std::lower_bound(begin, end, row);
    return L_.valuePtr()[it - L_.innerIndexPtr()];
  };
  for (int f = 0; f < g.n_faces; ++f) {
    Vec2 p[3];
    const double a2 = corners_2d(mesh, g, f, p);
    Eigen::Matrix<double, 2, 3>& G = gradient_[f];
    if (!(a2 > 0) || !std::isfinite(a2)) {  // degenerate: no term
      G.setZero();
      area_[f] = 0;
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      const Vec2 e = p[(k + 2) % 3] - p[(k + 1) % 3];
      G.col(k) = Vec2(-e.y(), e.x()) / a2;
    }
    area_[f] = 0.5 * a2;
    const Eigen::Matrix3d M = area_[f] * G.transpose() * G;
    const auto& fv = g.face_vertices[f];
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l) {
        const int a = free_index_[fv[k]], b = free_index_[fv[l]];
        if (a >= 0 && b >= 0 && a >= b) slot(a, b) += M(k, l);
      }
  }
  // A free vertex whose faces are all degenerate: s there is 0 (identity row).
  for (int i = 0; i < L_.cols(); ++i) {
    double& d = slot(i, i);
    if (!(d > 0)) d = 1.0;
  }
}

const SizingField& SizingSolver::solve(const TriMesh& mesh, const GeometryCache& g,
                                       const std::vector<double>& theta,
                                       const std::vector<int>& period_jump) {
  if (!same_connectivity(g))
    throw InvalidInputError("sizing: the mesh connectivity changed since the solver was built");
  check_sizes(g, theta, period_jump, {});
  // The Laplacian depends on positions only: refactorize when its values changed.
  assemble(mesh, g);
  const std::vector<double> values(L_.valuePtr(), L_.valuePtr() + L_.nonZeros());
  result_.refactorized = false;
  if (values != last_values_ || !solver_.factorized()) {
    if (L_.cols() > 0) solver_.factorize(L_);
    last_values_ = values;
    result_.refactorized = true;
  }
  // Target gradient g_t = −curl(v̂) û + curl(û) v̂, zero next to singular vertices.
  std::vector<char> excluded(g.n_faces, 0);
  if (options_.exclude_singular_faces) {
    const std::vector<int> index = quarter_indices_from_jumps(g, period_jump);
    for (int f = 0; f < g.n_faces; ++f)
      for (int v : g.face_vertices[f])
        if (index[v] != 0) excluded[f] = 1;
  }
  Eigen::VectorXd b = Eigen::VectorXd::Zero(L_.cols());
  result_.excluded_faces = 0;
  for (int f = 0; f < g.n_faces; ++f) {
    if (excluded[f]) {
      ++result_.excluded_faces;
      continue;
    }
    if (area_[f] <= 0) continue;
    Vec2 p[3];
    const double a2 = corners_2d(mesh, g, f, p);
    double cu, cv;
    face_curl(g, p, a2, f, face_edges_[f], theta, period_jump, {}, cu, cv);
    const Vec2 u(std::cos(theta[f]), std::sin(theta[f])), v(-u.y(), u.x());
    const Vec2 target = -cv * u + cu * v;
    const Eigen::Vector3d rhs = area_[f] * gradient_[f].transpose() * target;
    for (int k = 0; k < 3; ++k) {
      const int a = free_index_[g.face_vertices[f][k]];
      if (a >= 0) b(a) += rhs(k);
    }
  }
  const Eigen::VectorXd x = L_.cols() > 0 ? solver_.solve(b) : Eigen::VectorXd();
  std::vector<double>& sv = result_.vertex_log_scale;
  sv.assign(g.n_vertices, 0.0);
  for (int v = 0; v < g.n_vertices; ++v)
    if (free_index_[v] >= 0) sv[v] = x(free_index_[v]);
  std::vector<double> s(g.n_faces, 0.0);
  for (int f = 0; f < g.n_faces; ++f) {
    const auto& fv = g.face_vertices[f];
    s[f] = (sv[fv[0]] + sv[fv[1]] + sv[fv[2]]) / 3.0;
  }
  // Per component: shift c with Σ A e^{2 clamp(s + c)} = Σ A (monotone in c: bisection).
  const double clamp = options_.clamp;
  std::vector<std::vector<int>> faces_of(components_);
  for (int f = 0; f < g.n_faces; ++f) faces_of[component_[g.face_vertices[f][0]]].push_back(f);
  std::vector<double> shift(components_, 0.0);
  auto clamped = [clamp](double x) { return std::clamp(x, -clamp, clamp); };
  for (int c = 0; c < components_; ++c) {
    const auto& faces = faces_of[c];
    double total = 0, lo = 0, hi = 0;
    bool first = true;
    for (int f : faces) {
      total += g.face_area[f];
      lo = first ? s[f] : std::min(lo, s[f]);
      hi = first ? s[f] : std::max(hi, s[f]);
      first = false;
    }
    if (faces.empty() || !(total > 0)) {
      shift[c] = -0.5 * (lo + hi);
      continue;
    }
    // Without an active clamp the shift has a closed form; bisection only when it clamps.
    double weighted = 0;
    for (int f : faces) weighted += g.face_area[f] * std::exp(2 * (s[f] - hi));
    const double closed = -hi - 0.5 * std::log(weighted / total);
    if (hi + closed <= clamp && lo + closed >= -clamp) {
      shift[c] = closed;
      continue;
    }
    auto excess = [&](double cc) {
      double sum = 0;
      for (int f : faces) sum += g.face_area[f] * std::exp(2 * clamped(s[f] + cc));
      return sum - total;
    };
    double a = -clamp - hi, z = clamp - lo;  // excess(a) ≤ 0 ≤ excess(z)
    for (int it = 0; it < 100 && z - a > 1e-13 * (1 + std::abs(a)); ++it) {
      const double m = 0.5 * (a + z);
      (excess(m) < 0 ? a : z) = m;
    }
    shift[c] = 0.5 * (a + z);
  }
  result_.log_scale.assign(g.n_faces, 0.0);
  result_.clamped_faces = 0;
  for (int f = 0; f < g.n_faces; ++f) {
    const double raw = s[f] + shift[component_[g.face_vertices[f][0]]];
    result_.log_scale[f] = clamped(raw);
    result_.clamped_faces += std::abs(raw) > clamp;
  }
  for (int v = 0; v < g.n_vertices; ++v) sv[v] += shift[component_[v]];
  return result_;
}

SizingField compute_sizing(const TriMesh& mesh, const GeometryCache& g,
                           const std::vector<double>& theta, const std::vector<int>& period_jump,
                           const SizingOptions& options) {
  SizingSolver solver(mesh, g, options);
  return solver.solve(mesh, g, theta, period_jump);
}

}  // namespace qs
