// Curl-reducing sizing field (paper §5.3 after [RLL*06]; docs/design.md, "Sizing field"): a
// per-face log-scale s_t such that the scaled cross field e^{s} û, e^{s} v̂ is as close to curl-free
// (integrable, i.e. the gradient of a parameterization) as a scalar scale can make it. The
// parameterization then aims at ∇u = e^{s_t} u_t, ∇v = e^{s_t} v_t instead of the unit targets.
//
// Derivation. With curl(f w) = f curl w + ∇f × w and ∇s × û = −∇s·v̂, ∇s × v̂ = ∇s·û,
// curl(e^s û) = 0 and curl(e^s v̂) = 0 hold iff ∇s·v̂ = curl û and ∇s·û = −curl v̂, i.e.
// ∇s = g with g = −curl(v̂) û + curl(û) v̂. The discrete s is piecewise linear on the vertices
// and solves min_s Σ_t A_t ‖∇_t s − g_t‖² (cotan Laplacian, natural boundary conditions).
// g does not change under a global rotation of the field (θ_t → θ_t + φ), so neither does s.
//
// Discrete curl of a per-face unit field w (û or v̂): curl_t(w) = (1/A_t) Σ_{e∈t} ½ [w]_e·e,
// with e the edge vector, counter-clockwise in t, and [w]_e the jump w_{t'} − w_t across e, w_{t'}
// carried into t's plane (κ) and matched by the period jump: in t's frame the direction of the
// neighbour matched to û_t has the angle θ_t + δ, δ = ±(θ_j − θ_i − κ_e − p_e·π/2). Boundary
// edges have no jump (natural boundary conditions); a face with m < 3 interior edges divides
// their circulation by its area share m·A_t/3 instead of A_t (else the curl is biased toward
// 0 along the boundary, which bends s there). Pointwise, this per-face curl oscillates
// from face to face on irregular triangulations (alternating diagonals: O(1) even for a
// curl-free field); the least-squares fit of ∇s averages the oscillation out (on a radial field
// over an annulus, s matches the exact −log r within 0.05 — tests/sizing_test.cpp).
//
// Normalization and clamp. s is fixed up to one constant per connected component. The
// constant c is chosen so that the sized target field has the total squared length of the unit
// field, Σ_t A_t e^{2 s_t} = Σ_t A_t per component, after clamping |s_t| ≤ clamp (the constant
// is found with the clamp applied: in closed form when no face clamps, else by bisection; the
// clamp always holds). So the residual E of
// energy (1) keeps its scale (E/Σ 2A_t is the relative residual with and without sizing); a
// zero area-weighted mean would inflate every target by Jensen's inequality. Near a cone the
// exact scale is logarithmic (s ~ c·log r), so the curl there is dominated by the
// singularity: by default the faces incident to a singular vertex get g_t = 0 (they follow
// their neighbours), and the clamp bounds what remains.
#pragma once

#include <Eigen/Sparse>
#include <memory>
#include <vector>

#include "core/base/spd_solver.h"
#include "core/mesh/geometry.h"
#include "core/mesh/mesh.h"

namespace qs {

struct SizingOptions {
  //! Scale the parameterization's targets by e^{s_t} (ParamOptions::sizing). Off by default:
  //! with fixed nodes it lowers the residual E, but the node optimization recovers displaced
  //! layouts less closely and more slowly with it (docs/benchmarks.md, "Design measurements").
  //! `optimize --sizing` enables it.
  bool enabled = false;
  //! |s_t| ≤ clamp (a factor e^{±clamp} on the target length). Finite and ≥ 0.
  double clamp = 2.0;
  //! Faces incident to a singular vertex (interior index ≠ 0 from the period jumps) get
  //! g_t = 0: their curl is the cone's, which no smooth scale can remove.
  bool exclude_singular_faces = true;
  //! When non-empty (size #F): these s_t are used as they are instead of being solved for
  //! (a frozen sizing field, e.g. for finite differences with the field and s held fixed).
  std::vector<double> frozen_log_scale;
};

//! Per-face discrete curls of the matched field directions û and v̂ (docs/design.md, "Sizing
//! field"), optionally of the scaled field e^{s} û, e^{s} v̂. Units: 1/length.
struct FieldCurl {
  std::vector<double> u, v;  //!< size #F each
};

//! The discrete curls above. \p theta: per face angle of u_t from r_t (radians, size #F);
//! \p period_jump: per edge (canonical dual orientation, size #E); \p log_scale: per face s_t
//! (size #F) or empty (s = 0). Degenerate faces (zero area) get curl 0.
//! \throw InvalidInputError when a size does not match the geometry.
FieldCurl field_curl(const TriMesh& mesh, const GeometryCache& geometry,
                     const std::vector<double>& theta, const std::vector<int>& period_jump,
                     const std::vector<double>& log_scale = {});

struct SizingField {
  std::vector<double> log_scale;         //!< s_t per face (dimensionless, |s_t| ≤ clamp), size #F
  std::vector<double> vertex_log_scale;  //!< the unclamped, normalized s per vertex, size #V
  int clamped_faces = 0;                 //!< faces where the clamp was active
  int excluded_faces = 0;                //!< faces with g_t = 0 (next to a singularity)
  bool refactorized = false;             //!< the last solve factorized the Laplacian anew
};

//! Solver of the sizing field that keeps the cotan Laplacian's factorization: a new field
//! (θ) on the same geometry costs one back-substitution; new vertex positions cost a numeric
//! factorization, with CHOLMOD's symbolic analysis reused (the pattern depends only on the
//! connectivity). One vertex per connected component is pinned (the constant is fixed by the
//! normalization afterwards).
class SizingSolver {
 public:
  //! \throw InvalidInputError when options.clamp is negative or not finite.
  SizingSolver(const TriMesh& mesh, const GeometryCache& geometry,
               const SizingOptions& options = {});
  ~SizingSolver();
  SizingSolver(SizingSolver&&) noexcept;
  SizingSolver& operator=(SizingSolver&&) noexcept;

  //! Computes s for the field (\p theta, \p period_jump) on the current geometry (positions
  //! may have changed since construction; connectivity may not).
  //! \throw InvalidInputError when a size does not match; SolverError from CHOLMOD.
  const SizingField& solve(const TriMesh& mesh, const GeometryCache& geometry,
                           const std::vector<double>& theta, const std::vector<int>& period_jump);

  //! True when \p geometry has the connectivity this solver was built for.
  bool same_connectivity(const GeometryCache& geometry) const;
  const SizingOptions& options() const { return options_; }
  const SizingField& result() const { return result_; }
  const SpdSolver& linear_solver() const { return solver_; }

 private:
  void assemble(const TriMesh& mesh, const GeometryCache& geometry);

  SizingOptions options_;
  std::vector<std::array<int, 3>> face_vertices_;  // connectivity check
  std::vector<std::array<int, 3>> face_edges_;     // edge of corner k → k+1, per face
  std::vector<int> free_index_;                    // per vertex: unknown index, −1 when pinned
  std::vector<int> component_;                     // per vertex: connected component
  int components_ = 0;
  Eigen::SparseMatrix<double> L_;  // reduced cotan Laplacian (free × free, lower triangle)
  std::vector<double> last_values_;
  std::vector<Eigen::Matrix<double, 2, 3>> gradient_;  // per face ∇φ_k in the face frame
  std::vector<double> area_;
  SpdSolver solver_{"sizing field"};
  SizingField result_;
};

//! One-shot sizing field (builds a SizingSolver and solves once).
SizingField compute_sizing(const TriMesh& mesh, const GeometryCache& geometry,
                           const std::vector<double>& theta, const std::vector<int>& period_jump,
                           const SizingOptions& options = {});

}  // namespace qs
