#include "core/nodeopt/stiffening.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "core/nodeopt/gradient.h"

namespace qs {

std::vector<double> face_distortion(const TriMesh& mesh, const GeometryCache& g,
                                    const std::vector<std::array<double, 2>>& uv) {
  std::vector<double> out(g.n_faces, 0.0);
  for (int f = 0; f < g.n_faces; ++f) {
    const auto& fv = g.face_vertices[f];
    const Vec3& r = g.face_frame[f];
    const Vec3 s = g.face_normal[f] % r;
    const Vec3 x0 = mesh.point(mesh.vertex_handle(fv[0]));
    Eigen::Matrix2d P, U;  // columns: edge vectors in 3D frame / in (u, v)
    for (int k = 1; k < 3; ++k) {
      const Vec3 d = mesh.point(mesh.vertex_handle(fv[k])) - x0;
      P.col(k - 1) = Eigen::Vector2d(d | r, d | s);
      U.col(k - 1) =
          Eigen::Vector2d(uv[3 * f + k][0] - uv[3 * f][0], uv[3 * f + k][1] - uv[3 * f][1]);
    }
    if (std::abs(P.determinant()) <= 0) continue;
    const Eigen::Matrix2d J = U * P.inverse();
    Eigen::JacobiSVD<Eigen::Matrix2d> svd(J);
    const double tau = J.determinant() <= 0 ? -1.0 : 1.0;
    const auto sv = svd.singularValues();
    out[f] = std::abs(tau * sv(0) - 1) + std::abs(tau * sv(1) - 1);
  }
  return out;
}

StiffeningResult stiffen(const TriMesh& mesh, const Layout& layout, const PipelineOptions& options,
                         const StiffeningOptions& st, const Observer* observer) {
  StiffeningResult out;
  PipelineOptions opt = options;
  const int nf = static_cast<int>(mesh.n_faces());
  if (opt.param.face_weights.empty()) opt.param.face_weights.assign(nf, 1.0);
  int best_folds = -1;
  double best_E = 0;
  for (int it = 0; it <= st.max_iterations; ++it) {
    check_cancel(observer);
    Pipeline p(mesh, layout, opt);
    p.compute_field();
    const Parameterization& r = p.compute_parameterization();
    const double E =
        unweighted_energy(p.mesh(), p.geometry(), p.field()->theta, r, opt.param);
    if (it == 0) {
      out.foldovers_before = r.foldovers;
      out.E_before = E;
    }
    if (best_folds < 0 || r.foldovers < best_folds || (r.foldovers == best_folds && E < best_E)) {
      best_folds = r.foldovers;
      best_E = E;
      out.face_weights = opt.param.face_weights;
      out.foldovers_after = r.foldovers;
      out.E_after = E;
    }
    if (r.foldovers == 0 || it == st.max_iterations) break;
    out.iterations = it + 1;
    const GeometryCache& g = p.geometry();
    const std::vector<double> D = face_distortion(p.mesh(), g, r.corner_uv);
    std::vector<double> L(nf, 0.0);
    std::vector<int> count(nf, 0);
    for (int e = 0; e < g.n_edges; ++e) {
      const int i = g.edge_face_i[e], j = g.edge_face_j[e];
      if (i < 0 || j < 0) continue;
      L[i] -= D[j];
      L[j] -= D[i];
      ++count[i];
      ++count[j];
    }
    for (int f = 0; f < nf; ++f) {
      L[f] += count[f] * D[f];
      opt.param.face_weights[f] += std::min(st.factor * std::abs(L[f]), st.max_increment);
    }
  }
  return out;
}

}  // namespace qs
