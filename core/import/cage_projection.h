// Projecting a subdivided quad structure (core/import/dense_cage.h) onto a target triangle mesh,
// and finding where the projection folds (docs/design.md, "Transfer").
#pragma once

#include <vector>

#include "core/import/dense_cage.h"
#include "core/mesh/mesh.h"
#include "core/mesh/surface_point.h"

namespace qs {

struct CageProjectionOptions {
  //! Vertices whose distance from the target exceeds this fraction of their mean edge length
  //! make the projection a flow: `flow_steps` steps that each move every vertex part of the
  //! way towards its closest point and then smooth it within the surface's tangent plane
  //! (neighbours cannot swap), before the final closest-point projection. In (0, 100].
  double flow_offset = 0.25;
  //! Steps of that flow. In [1, 1000].
  int flow_steps = 8;
  //! Rounds of relaxation where the projection folds (see project_cage). In [0, 1000].
  int relax_rounds = 30;
};

//! The dense cage on the target surface.
struct ProjectedCage {
  //! Per dense vertex (size #V of the dense mesh): its point on the target, and its position.
  std::vector<SurfacePoint> point;
  std::vector<Vec3> position;
  //! Per dense vertex: its distance from the target before the projection (model units).
  std::vector<double> offset;
  //! Largest offset relative to the vertex's mean edge length (decides the flow).
  double max_relative_offset = 0;
  //! Flow steps taken (0: every vertex went straight to its closest point).
  int flow_steps = 0;
  //! Vertices moved by the relaxation of folds.
  int relaxed_vertices = 0;
  //! Per dense edge (size #E): for boundary edges, the midpoint of its projected ends projected
  //! onto the target's boundary; face -1 for the other edges.
  std::vector<SurfacePoint> boundary_midpoint;
};

//! Projects every vertex of \p cage.mesh (the dense cage) onto \p target: vertices on the
//! boundary of the dense cage go to the closest point of the target's boundary, the others to
//! the closest surface point (moved into the face, a tenth of the way to its centroid, when that
//! point lies on the target's boundary). Interior vertices flow first when the offset is large
//! (CageProjectionOptions). Where the cage itself lies on the target, its own surface is used
//! instead of the smoothed one: a quad-structure vertex whose own position lies at most as far
//! from the target as its smoothed position (or within 1e-3 of its mean edge length) goes to
//! the closest point of its own position, and so does every dense vertex all of whose faces lie
//! in quads with such corners only, at its DenseCage::linear position (a quad mesh on the
//! surface keeps its vertices and edges, features included; a cage off the surface takes its
//! subdivided positions).
//! Where the result folds (a projected face turned against the target's normals, or a vertex
//! whose neighbours do not wind once around it, see find_folds), the folded vertices and a few
//! rings around them move to the mean of their neighbours and back onto the target (boundary
//! vertices along the boundary), round after round, until nothing folds or
//! options.relax_rounds are used up: first with the vertices at their own positions kept in
//! place, then, when that leaves folds, with all of them free; find_folds reports what still
//! folds.
//! \throw InvalidInputError also when \p cage is inconsistent (sizes of linear or
//!        quad_of_face).
//! \throw InvalidInputError when \p dense has a boundary and \p target has none, or the options
//!        are out of range.
ProjectedCage project_cage(const DenseCage& cage, const TriMesh& target,
                           const CageProjectionOptions& options = {});

//! Where a projected dense cage folds.
struct CageFolds {
  //! The target is oriented against the cage (most projected faces face away from its normals).
  bool reversed = false;
  //! Quads of the quad structure holding a projected dense face whose orientation disagrees
  //! with the target's normals there (or that collapsed to no area), ascending.
  std::vector<int> quads;
  //! Those of the given vertices whose first dense neighbours, projected into the target's
  //! tangent plane, do not wind once around them in the cage's order (for a boundary vertex:
  //! do not sweep less than a full turn in the cage's order), ascending.
  std::vector<int> vertices;
};

//! Checks the projection of \p cage: every dense face's orientation against the target's face
//! normals at its corners, and the winding of the first dense neighbours around each of
//! \p vertices (indices of quad-structure vertices, which are dense vertices of the same index).
CageFolds find_folds(const DenseCage& cage, const ProjectedCage& projected, const TriMesh& target,
                     const std::vector<int>& vertices);

}  // namespace qs
