// Stiffening (paper §6; docs/design.md, "Stiffening"): raise per-face weights where
// the parameterization is flipped or distorted, and re-solve, to remove fold-overs.
#pragma once

#include <array>
#include <vector>

#include "core/base/progress.h"
#include "core/layout/layout.h"
#include "core/mesh/geometry.h"
#include "core/mesh/mesh.h"
#include "core/pipeline/pipeline.h"

namespace qs {

struct StiffeningOptions {
  int max_iterations = 10;     //!< re-solves at most
  double max_increment = 5.0;  //!< w_t += min(c·|L_t|, max_increment)
  double factor = 1.0;         //!< c above
};

struct StiffeningResult {
  std::vector<double> face_weights;  //!< final weights (size #F, ≥ 1)
  int iterations = 0;
  int foldovers_before = 0, foldovers_after = 0;
  double E_before = 0, E_after = 0;  //!< unweighted residual of (1) before / after
};

//! Per-face distortion D_t = |τσ₁ − 1| + |τσ₂ − 1| of the map from the face's 3D frame to (u,v)
//! (σ singular values, τ = −1 on flipped faces). Size #F, dimensionless.
std::vector<double> face_distortion(const TriMesh& mesh, const GeometryCache& geometry,
                                    const std::vector<std::array<double, 2>>& corner_uv);

//! Runs field + parameterization with growing face weights while fold-overs remain (at most
//! max_iterations re-solves). Returns the weights of the last solve (all 1 if there were no
//! fold-overs) and the fold-over counts. Keeps the weights of the best solve (fewest
//! fold-overs, then lowest E). \throw as Pipeline; Cancelled via \p observer.
StiffeningResult stiffen(const TriMesh& mesh, const Layout& layout, const PipelineOptions& options,
                         const StiffeningOptions& stiffening = {},
                         const Observer* observer = nullptr);

}  // namespace qs
