// The natural cross field of a bare mesh (no layout): the smoothest 4-direction field that
// follows the reliable curvature directions, sharp features and the boundary, with its
// singularities free. Where it has singularities is where a quad layout wants its irregular
// nodes (the editor's field hints).
//
// The field is solved as one complex number per face, z_f = e^{4iθ_f} (θ_f measured from the
// face frame r_f, GeometryCache), which makes the four directions of a cross one value:
//   min Σ_e w_e |z_j − e^{4iκ_ij} z_i|² + Σ_{f∈C} λ_f |z_f − e^{4iφ_f}|²
// over the interior edges e = (i, j) (w_e = edge length / distance of the face centroids, κ the
// connection) and the constrained faces C (φ_f: the constraint direction; λ_f: the feature and
// boundary weight, or the smaller curvature weight). With no constraint
// at all, the smoothest unit field is the eigenvector of the smallest eigenvalue of that
// connection Laplacian (by inverse iteration). A linear solve, no integer variables: the
// singularities are wherever the optimum puts them.
#pragma once

#include <vector>

#include "core/field/curvature.h"
#include "core/mesh/geometry.h"
#include "core/mesh/mesh.h"

namespace qs {

struct NaturalFieldOptions {
  //! Which constraints hold the field (curvature, features, all boundary edges) and their
  //! thresholds; collect_constraints without a layout.
  ConstraintOptions constraints;
  //! λ of a face constrained by a feature or the boundary, against the smoothness of one edge.
  //! > 0.
  double constraint_weight = 1.0;
  //! λ of a face constrained by its curvature directions: small, so that the field follows the
  //! curvature where it is consistent and smooths over its noise (every contradiction between
  //! nearby constrained faces would otherwise cost a pair of singularities). > 0.
  double curvature_weight = 0.1;
  //! Inverse iterations for a mesh without constraints. In [1, 1000].
  int iterations = 60;
};

//! \throw InvalidInputError naming the option when a value is out of range or not finite.
void validate_natural_field_options(const NaturalFieldOptions& options);

//! A singularity of the field: an interior vertex whose index is not 0.
struct FieldSingularity {
  int vertex = -1;
  //! Index in quarter turns: +1 where a node of valence 3 belongs, −1 for valence 5, …
  int index = 0;
};

struct NaturalField {
  std::vector<double> theta;    //!< per face: angle of the first direction from r_f (radians)
  std::vector<Vec3> direction;  //!< per face: the first direction (unit, in the face plane)
  //! Per vertex (size #V): index in quarter turns on the field alone (field_quarter_indices;
  //! 0 on the boundary).
  std::vector<int> quarter_index;
  std::vector<FieldSingularity> singularities;  //!< the vertices with a non-zero index
  FieldConstraints constraints;                 //!< the direction constraints used
  double bbox_diagonal = 0;  //!< the mesh's bounding-box diagonal (GeometryCache), model units
};

//! The singularities of \p singularities that remain at the length scale \p radius (model
//! units): pairs of opposite index (a and −a) whose vertices are closer than \p radius along
//! mesh edges cancel, the closest pair first (ties: the lower vertex indices first). A quad
//! layout whose patches are larger than \p radius cannot resolve such a pair, so it places no
//! irregular nodes there. The rest keep their order; the index sum is unchanged.
//! \p radius ≤ 0 keeps all. Deterministic; costs one Dijkstra ball of \p radius per
//! singularity.
//! \throw InvalidInputError when \p radius is not finite or a vertex is out of range.
std::vector<FieldSingularity> cancel_close_pairs(const TriMesh& mesh,
                                                 const std::vector<FieldSingularity>& singularities,
                                                 double radius);

//! The natural cross field of \p mesh (\p geometry: build_geometry of it).
//! \throw InvalidInputError for invalid options, SolverError when the solve fails.
NaturalField compute_natural_field(const TriMesh& mesh, const GeometryCache& geometry,
                                   const NaturalFieldOptions& options = {});

}  // namespace qs
