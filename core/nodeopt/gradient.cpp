#include "core/nodeopt/gradient.h"

#include <Eigen/Dense>
#include <cmath>
#include <string>

#include "core/base/errors.h"

namespace qs {

namespace {

// ∂E_t/∂x of one face's term of (1) for its corner k (docs/design.md, "Gradient"), as a 3D
// vector in the face plane. The face's 2D frame is (r_f, n_f × r_f), as in the parameterization.
Vec3 face_corner_gradient(const TriMesh& mesh, const GeometryCache& g, double theta,
                          const std::vector<std::array<double, 2>>& uv, double aniso, double weight,
                          double target_scale, int f, int k) {
  const auto corners = face_corners_2d(mesh, g, f);
  Eigen::Vector2d p[3];
  for (int c = 0; c < 3; ++c) p[c] = Eigen::Vector2d(corners[c][0], corners[c][1]);
  const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
  const double a2 = (p[1] - p[0]).x() * (p[2] - p[0]).y() - (p[1] - p[0]).y() * (p[2] - p[0]).x();
  auto J = [](const Eigen::Vector2d& e) { return Eigen::Vector2d(-e.y(), e.x()); };
  // Gradient of a linear function with corner values c: J(Σ c_i e_i)/(2A), e_i opposite i.
  auto grad = [&](const double c[3]) {
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    for (int i = 0; i < 3; ++i) sum += c[i] * (p[(i + 2) % 3] - p[(i + 1) % 3]);
    return Eigen::Vector2d(J(sum) / a2);
  };
  // Targets e^{s_t} u_t, e^{s_t} v_t (sizing, s_t frozen); the norms W use the unit directions.
  const Eigen::Vector2d u(std::cos(theta), std::sin(theta)), v(-u.y(), u.x());
  const Eigen::Vector2d su = target_scale * u, sv = target_scale * v;
  const Eigen::Matrix2d Wu = u * u.transpose() + aniso * v * v.transpose();
  const Eigen::Matrix2d Wv = v * v.transpose() + aniso * u * u.transpose();
  const Eigen::Vector2d Je0 = J(p[k2] - p[k1]);
  Eigen::Matrix2d Jm;
  Jm << 0, -1, 1, 0;
  Eigen::Vector2d total = Eigen::Vector2d::Zero();
  for (int c = 0; c < 2; ++c) {
    const double val[3] = {uv[3 * f][c], uv[3 * f + 1][c], uv[3 * f + 2][c]};
    const Eigen::Vector2d gr = grad(val);
    const Eigen::Vector2d& target = c == 0 ? su : sv;
    const Eigen::Matrix2d& W = c == 0 ? Wu : Wv;
    const Eigen::Vector2d res = gr - target;
    const Eigen::Vector2d Wr = W * res;
    total += (val[k1] - val[k2]) * (Jm.transpose() * Wr) + (0.5 * res.dot(Wr) - gr.dot(Wr)) * Je0;
  }
  total *= weight;
  const Vec3& r = g.face_frame[f];
  return total.x() * r + total.y() * (g.face_normal[f] % r);
}

}  // namespace

Vec3 vertex_normal(const TriMesh& mesh, const GeometryCache& g, int vertex) {
  Vec3 n(0, 0, 0);
  for (auto fh : mesh.vf_range(mesh.vertex_handle(vertex)))
    n += g.face_area[fh.idx()] * g.face_normal[fh.idx()];
  const double len = n.norm();
  return len > 0 ? n / len : Vec3(0, 0, 1);
}

void tangent_basis(const Vec3& n, Vec3& t1, Vec3& t2) {
  const Vec3 a = std::abs(n[0]) < 0.6 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
  t1 = (a - (a | n) * n).normalized();
  t2 = n % t1;
}

Vec3 estimate_vertex_gradient(const TriMesh& mesh, const GeometryCache& g,
                              const std::vector<double>& theta,
                              const std::vector<std::array<double, 2>>& uv,
                              const ParamOptions& options, int vertex,
                              const std::vector<double>& log_scale) {
  if (!log_scale.empty() && static_cast<int>(log_scale.size()) != g.n_faces)
    throw InvalidInputError("node gradient: " + std::to_string(log_scale.size()) +
                            " sizing log-scales for " + std::to_string(g.n_faces) + " faces");
  const double aniso = options.anisotropic ? options.anisotropy : 1.0;
  Vec3 sum(0, 0, 0);
  for (auto fh : mesh.vf_range(mesh.vertex_handle(vertex))) {
    const int f = fh.idx();
    const int k = corner_of(g, f, vertex);
    const double w = options.face_weights.empty() ? 1.0 : options.face_weights[f];
    const double scale = log_scale.empty() ? 1.0 : std::exp(log_scale[f]);
    sum += face_corner_gradient(mesh, g, theta[f], uv, aniso, w, scale, f, k);
  }
  const Vec3 n = vertex_normal(mesh, g, vertex);
  return sum - (sum | n) * n;
}

std::vector<Vec3> estimate_node_gradients(const TriMesh& mesh, const GeometryCache& g,
                                          const std::vector<double>& theta,
                                          const std::vector<std::array<double, 2>>& uv,
                                          const ParamOptions& options,
                                          const std::vector<int>& vertices,
                                          const std::vector<double>& log_scale) {
  std::vector<Vec3> out;
  out.reserve(vertices.size());
  for (int v : vertices)
    out.push_back(estimate_vertex_gradient(mesh, g, theta, uv, options, v, log_scale));
  return out;
}

std::vector<Vec3> estimate_node_gradients(const TriMesh& mesh, const GeometryCache& g,
                                          const std::vector<double>& theta,
                                          const Parameterization& param,
                                          const ParamOptions& options,
                                          const std::vector<int>& vertices) {
  return estimate_node_gradients(mesh, g, theta, param.corner_uv, options, vertices,
                                 param.sizing_log_scale);
}

std::vector<double> freeze_field_after_move(const TriMesh& mesh, const GeometryCache& before,
                                            const GeometryCache& after,
                                            const std::vector<double>& theta, int vertex) {
  std::vector<double> out = theta;
  for (auto fh : mesh.vf_range(mesh.vertex_handle(vertex))) {
    const int f = fh.idx();
    const int k = corner_of(after, f, vertex);
    const auto& fv = after.face_vertices[f];
    const Vec3 e = mesh.point(mesh.vertex_handle(fv[(k + 2) % 3])) -
                   mesh.point(mesh.vertex_handle(fv[(k + 1) % 3]));
    out[f] = theta[f] - before.angle_in_face(f, e) + after.angle_in_face(f, e);
  }
  return out;
}

double unweighted_energy(const TriMesh& mesh, const GeometryCache& g,
                         const std::vector<double>& theta,
                         const std::vector<std::array<double, 2>>& uv, const ParamOptions& options,
                         const std::vector<double>& log_scale) {
  ParamOptions plain = options;
  plain.face_weights.clear();
  double e = 0;
  for (double x : face_energies(mesh, g, theta, uv, plain, log_scale)) e += x;
  return e;
}

double unweighted_energy(const TriMesh& mesh, const GeometryCache& g,
                         const std::vector<double>& theta, const Parameterization& param,
                         const ParamOptions& options) {
  return unweighted_energy(mesh, g, theta, param.corner_uv, options, param.sizing_log_scale);
}

std::vector<Vec3> exact_node_gradients(const TriMesh& mesh, const Layout& layout,
                                       const PipelineOptions& options,
                                       const std::vector<int>& vertices,
                                       const ExactGradientOptions& fd, const Observer* observer) {
  const GeometryCache g = build_geometry(mesh);
  const double eps = fd.relative_step * g.mean_edge_length;
  auto energy_at = [&](int v, const Vec3& x) {
    check_cancel(observer);
    TriMesh moved = mesh;
    moved.set_point(moved.vertex_handle(v), x);
    Pipeline p(std::move(moved), layout, options);
    p.compute_field();
    const Parameterization& r = p.compute_parameterization();
    return unweighted_energy(p.mesh(), p.geometry(), p.field()->theta, r, options.param);
  };
  std::vector<Vec3> out;
  out.reserve(vertices.size());
  for (int v : vertices) {
    Vec3 t[2];
    tangent_basis(vertex_normal(mesh, g, v), t[0], t[1]);
    const Vec3 x = mesh.point(mesh.vertex_handle(v));
    Vec3 grad(0, 0, 0);
    for (const Vec3& dir : t) {
      const double d = (energy_at(v, x + eps * dir) - energy_at(v, x - eps * dir)) / (2 * eps);
      grad += d * dir;
    }
    out.push_back(grad);
  }
  return out;
}

}  // namespace qs
