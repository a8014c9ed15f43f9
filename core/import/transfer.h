// Transferring a quad layout (the base complex of a quad mesh or subdivision cage, or all its
// edges) onto a triangle mesh that the quad structure lies on or near, on a working mesh of
// that triangle mesh (docs/design.md, "Transfer").
#pragma once

#include <memory>
#include <vector>

#include "core/import/base_complex.h"
#include "core/layout/embed.h"
#include "core/layout/layout.h"
#include "core/mesh/mesh.h"
#include "core/mesh/working_mesh.h"

namespace qs {

struct TransferOptions {
  //! A point of the subdivided quad structure farther than this fraction of the target's
  //! bounding-box diagonal from the target's surface is an error. In (0, 1].
  double max_distance_fraction = 0.05;
  //! The quad structure is subdivided until its mean edge length is at most this many mean
  //! edge lengths of the target. In [0.5, 100].
  double dense_edge_factor = 2.0;
  //! Discretization of the layout (EmbedOptions::through_points is always on).
  EmbedOptions embed;
};

//! \throw InvalidInputError naming the option when a value is out of range or not finite.
void validate_transfer_options(const TransferOptions& options);

struct TransferStats {
  int levels = 0;  //!< Catmull–Clark steps of the cage
  int dense_vertices = 0, dense_faces = 0;
  double max_offset = 0;     //!< largest distance of a dense vertex from the target / bbox diagonal
  int flow_steps = 0;        //!< steps of the projection flow (0: closest points)
  int relaxed_vertices = 0;  //!< dense vertices moved where the projection folded
  bool reversed = false;     //!< the target is oriented against the quad structure
  int input_vertices = 0, input_faces = 0;      //!< the target mesh
  int working_vertices = 0, working_faces = 0;  //!< the working mesh
  double growth = 1;                            //!< working faces / target faces
  double max_origin_error = 0;                  //!< WorkingMesh::max_origin_error()
  double min_angle_deg = 0;                     //!< WorkingMesh::min_angle_deg()
  EmbedStats embed;
  double subdivide_s = 0, project_s = 0, embed_s = 0, check_s = 0;  //!< wall-clock seconds
};

struct TransferResult {
  std::shared_ptr<WorkingMesh> mesh;
  //! The layout on mesh->mesh(): node i and arc a of the complex have id i and a, nodes by
  //! vertex (no points), arcs by edge path; mesh_vertices/mesh_faces give the working mesh's
  //! size.
  Layout layout;
  TransferStats stats;
};

//! Transfers \p complex, a layout on \p quads, onto \p target:
//! 1. \p cage (the quad mesh, or a subdivision cage with n-gons, whose split into quads is
//!    \p quads) is subdivided by Catmull–Clark until its edges are about
//!    options.dense_edge_factor target edges long (subdivide_cage);
//! 2. its vertices are projected onto the target (project_cage: boundary onto boundary, a
//!    smoothing flow where the offset is large), and every projected face and node is checked
//!    for folds (find_folds);
//! 3. nodes become surface points (the projected quad vertices), arcs the polylines of their
//!    projected dense vertices, and the layout is embedded on a working mesh of the target
//!    (embed_layout, through the points);
//! 4. the result must validate (validate_layout), have the complex's patch count and keep every
//!    node's cyclic order of arcs (reversed when the target is oriented against the cage).
//! \throw InvalidInputError: a point farther than the tolerance (naming the nodes and quads), a
//!        boundary without a boundary to go to, folded quads and nodes (by id), arcs that cannot
//!        be routed (by id), validation errors, a patch count or cyclic order that differs.
TransferResult transfer_quads(const PolyMesh& cage, const PolyMesh& quads,
                              const QuadComplex& complex, std::shared_ptr<const TriMesh> target,
                              const TransferOptions& options = {});

}  // namespace qs
