// Quality metrics of a parameterization (paper §9.1; docs/design.md, "Metrics").
#pragma once

#include <array>
#include <vector>

#include "core/field/curvature.h"
#include "core/mesh/geometry.h"
#include "core/mesh/mesh.h"

namespace qs {

struct ParamMetrics {
  double E = 0;  //!< residual of energy (1) as minimized (length² units)
  //! Area-weighted mean of σ1/σ2 + σ2/σ1 (2 = conformal) over the faces whose parametric
  //! image is not degenerate (see `degenerate`).
  double E_confor = 0;
  double E_angle_deg = 0;  //!< E°: curvature-weighted deviation of the iso-lines from the
                           //!< principal directions, degrees in [0, 45]
  double E_planar = 0;     //!< conjugacy: (1/√A) Σ A_t |âᵀ S_t b̂| (dimensionless)
  int foldovers = 0;       //!< faces with signed parametric area ≤ 0
  //! Faces mapped to (almost) a segment or a point: σ2 ≤ kDegenerateRatio·σ1 (also counted in
  //! `foldovers`). Their σ1/σ2 is unbounded, so they are left out of E_confor's mean instead of
  //! dominating it (a single collinear face gave E_confor ≈ 1e28).
  int degenerate = 0;
  static constexpr double kDegenerateRatio = 1e-8;
};

//! Computes the metrics of corner values \p corner_uv (size 3·#F). \p energy is copied into E.
ParamMetrics compute_metrics(const TriMesh& mesh, const GeometryCache& geometry,
                             const Curvature& curvature,
                             const std::vector<std::array<double, 2>>& corner_uv, double energy);

}  // namespace qs
