#include "core/extract/metrics.h"

#include <Eigen/Dense>
#include <cmath>

namespace qs {

ParamMetrics compute_metrics(const TriMesh& mesh, const GeometryCache& g, const Curvature& curv,
                             const std::vector<std::array<double, 2>>& uv, double energy) {
  ParamMetrics m;
  m.E = energy;
  double area_sum = 0, confor = 0, confor_area = 0, angle_num = 0, angle_den = 0, planar = 0;
  auto deviation_deg = [](const Eigen::Vector2d& v, const Eigen::Vector2d& d) {
    const double a = std::atan2(v.y(), v.x()) - std::atan2(d.y(), d.x());
    return std::abs(std::remainder(a, M_PI / 2)) * 180.0 / M_PI;
  };
  for (int f = 0; f < g.n_faces; ++f) {
    const auto corners = face_corners_2d(mesh, g, f);
    Eigen::Vector2d p[3];
    for (int c = 0; c < 3; ++c) p[c] = Eigen::Vector2d(corners[c][0], corners[c][1]);
    Eigen::Matrix2d E3, Euv;
    E3.col(0) = p[1] - p[0];
    E3.col(1) = p[2] - p[0];
    Euv << uv[3 * f + 1][0] - uv[3 * f][0], uv[3 * f + 2][0] - uv[3 * f][0],
        uv[3 * f + 1][1] - uv[3 * f][1], uv[3 * f + 2][1] - uv[3 * f][1];
    const double a = g.face_area[f];
    area_sum += a;
    if (Euv.determinant() <= 0) ++m.foldovers;
    if (std::abs(E3.determinant()) < 1e-300) continue;
    if (!Euv.allFinite()) {  // a failed solve: no meaningful term for this face
      ++m.degenerate;
      continue;
    }
    const Eigen::Matrix2d J = Euv * E3.inverse();               // rows: ∇u, ∇v
    const Eigen::Vector2d sv = J.jacobiSvd().singularValues();  // sv(0) ≥ sv(1) ≥ 0
    if (!(sv(1) > ParamMetrics::kDegenerateRatio * sv(0))) {
      ++m.degenerate;  // collapsed image: σ1/σ2 is unbounded
    } else {
      confor += a * (sv(0) / sv(1) + sv(1) / sv(0));
      confor_area += a;
    }
    const Eigen::Vector2d gu = J.row(0).transpose(), gv = J.row(1).transpose();
    const Vec3& d1 = curv.dir_max[f];
    const Vec3& r = g.face_frame[f];
    const Eigen::Vector2d d(d1 | r, d1 | (g.face_normal[f] % r));
    const double w = std::pow(curv.k_max[f] - curv.k_min[f], 2);
    angle_num += a * w * 0.5 * (deviation_deg(gu, d) + deviation_deg(gv, d));
    angle_den += a * w;
    const Eigen::Vector2d dn = d.normalized(), d2(-dn.y(), dn.x());
    const Eigen::Matrix2d S =
        curv.k_max[f] * dn * dn.transpose() + curv.k_min[f] * d2 * d2.transpose();
    if (gu.norm() > 0 && gv.norm() > 0)
      planar += a * std::abs(gu.normalized().dot(S * gv.normalized()));
  }
  if (area_sum > 0) {
    m.E_confor = confor_area > 0 ? confor / confor_area : 0.0;
    m.E_planar = planar / std::sqrt(area_sum);
  }
  m.E_angle_deg = angle_den > 0 ? angle_num / angle_den : 0.0;
  return m;
}

}  // namespace qs
