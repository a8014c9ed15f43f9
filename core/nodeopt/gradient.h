// Node gradients of the residual E of energy (1) (paper §7; docs/design.md, "Gradient"):
// the 1-ring estimator (exact with the field frozen, by the envelope theorem) and central
// finite differences that re-solve field and parameterization.
#pragma once

#include <array>
#include <vector>

#include "core/base/progress.h"
#include "core/layout/layout.h"
#include "core/mesh/geometry.h"
#include "core/mesh/mesh.h"
#include "core/param/parameterization.h"
#include "core/pipeline/pipeline.h"

namespace qs {

//! Area-weighted unit vertex normal (3D).
Vec3 vertex_normal(const TriMesh& mesh, const GeometryCache& geometry, int vertex);

//! An orthonormal pair (t1, t2) spanning the plane orthogonal to the unit vector \p n.
void tangent_basis(const Vec3& n, Vec3& t1, Vec3& t2);

//! ∂E/∂x_v of energy (1) at vertex \p vertex with the field and the parameterization held
//! fixed (docs/design.md, "Gradient"): the 1-ring sum of per-face analytic gradients (anisotropic
//! norm and ParamOptions::face_weights included), each with the field frozen relative to the edge
//! opposite the vertex, projected onto the tangent plane of the area-weighted vertex normal.
//! With sizing the targets are e^{s_t} u_t, e^{s_t} v_t, s_t held fixed per face like the field
//! (\p log_scale: Parameterization::sizing_log_scale, size #F, or empty for s = 0).
//! The descent direction d̃ is the negative of the result. Units: length (E ~ length²).
//! \pre theta (size #F) and corner_uv (size 3·#F) belong to the current mesh state.
//! \throw InvalidInputError when log_scale is neither empty nor of size #F.
Vec3 estimate_vertex_gradient(const TriMesh& mesh, const GeometryCache& geometry,
                              const std::vector<double>& theta,
                              const std::vector<std::array<double, 2>>& corner_uv,
                              const ParamOptions& options, int vertex,
                              const std::vector<double>& log_scale = {});

//! estimate_vertex_gradient for each vertex in \p vertices.
std::vector<Vec3> estimate_node_gradients(const TriMesh& mesh, const GeometryCache& geometry,
                                          const std::vector<double>& theta,
                                          const std::vector<std::array<double, 2>>& corner_uv,
                                          const ParamOptions& options,
                                          const std::vector<int>& vertices,
                                          const std::vector<double>& log_scale = {});

//! The same for a solved parameterization: its corner values and its sizing log-scale.
std::vector<Vec3> estimate_node_gradients(const TriMesh& mesh, const GeometryCache& geometry,
                                          const std::vector<double>& theta,
                                          const Parameterization& param,
                                          const ParamOptions& options,
                                          const std::vector<int>& vertices);

//! The "frozen field" after vertex \p vertex moved: faces incident to it keep the angle of u_t
//! against their edge opposite the vertex; other faces keep θ. \p before is the geometry before
//! the move, \p after (and \p mesh) after it. Returns θ' (size #F, radians).
std::vector<double> freeze_field_after_move(const TriMesh& mesh, const GeometryCache& before,
                                            const GeometryCache& after,
                                            const std::vector<double>& theta, int vertex);

struct ExactGradientOptions {
  //! Finite-difference step ε = relative_step · mean edge length.
  double relative_step = 1e-6;
};

//! dE/dx_v by central finite differences: the vertex is moved by ±ε along two tangent
//! directions (area-weighted normal) and field + parameterization are re-solved from scratch on
//! the displaced mesh with the same layout (4 full Pipeline solves per vertex). Returns 3D
//! tangent vectors (length units). Checks \p observer for cancellation between solves.
//! \throw InvalidInputError, TopologyError, SolverError from the pipeline; Cancelled.
std::vector<Vec3> exact_node_gradients(const TriMesh& mesh, const Layout& layout,
                                       const PipelineOptions& options,
                                       const std::vector<int>& vertices,
                                       const ExactGradientOptions& fd = {},
                                       const Observer* observer = nullptr);

//! Residual E of energy (1) without face weights: Σ face_energies (length² units), with the
//! targets scaled by e^{s_t} (\p log_scale, size #F, or empty for s = 0).
double unweighted_energy(const TriMesh& mesh, const GeometryCache& geometry,
                         const std::vector<double>& theta,
                         const std::vector<std::array<double, 2>>& corner_uv,
                         const ParamOptions& options, const std::vector<double>& log_scale = {});

//! The same for a solved parameterization: its corner values and its sizing log-scale (the
//! energy the solve minimized, without face weights). Use this form whenever sizing may be on.
double unweighted_energy(const TriMesh& mesh, const GeometryCache& geometry,
                         const std::vector<double>& theta, const Parameterization& param,
                         const ParamOptions& options);

}  // namespace qs
