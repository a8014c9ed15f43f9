// Cancelling nearby irregular vertices of a closed quad mesh by diagonal collapses and edge
// rotations (the simplified layouts of cage_layout, core/import/cage.h).
#pragma once

#include <vector>

#include "core/mesh/mesh.h"

namespace qs {

//! What cancel_irregular_vertices did.
struct CageSimplifyStats {
  int quads_before = 0, quads_after = 0;
  int irregular_before = 0, irregular_after = 0;  //!< vertices of valence != 4
  int collapses = 0, rotations = 0;               //!< operations applied
};

struct QuadSimplifyOptions {
  //! Rounds of look-ahead after the greedy pass (0: greedy only), see
  //! cancel_irregular_vertices.
  int rounds = 0;
  //! Neutral operations in a row before the improving one in a look-ahead (>= 1).
  int depth = 1;
  //! With surface normals: the smallest sin(corner angle) of a face an operation makes or
  //! changes (0.5: corners between 30° and 150°).
  double min_corner_sine = 0.5;
};

//! Cancels nearby irregular vertices of a closed pure quad mesh (e.g. the valence-3/5 pairs a
//! voxel staircase leaves about one cell apart) by local operations that keep it a closed
//! manifold quad mesh of the same genus:
//! - diagonal collapse of a quad (a, b, c, d): a and c merge at their midpoint (valence
//!   val(a) + val(c) − 2), b and d lose one edge;
//! - edge rotation: the edge between two quads turns to another diagonal of their hexagon (its
//!   ends lose one edge, two opposite hexagon corners gain one).
//! Every operation keeps all valences >= 3 (at most 8). Greedy pass: operations that lower
//! Σ (valence − 4)² are applied until there is none. Then, for options.rounds rounds, at each
//! irregular vertex: an operation that leaves the sum unchanged is kept when, after at most
//! options.depth − 1 further such operations at the irregular vertices it touched, an
//! improving one becomes possible nearby (moves a defect towards its partner).
//! \param normals if given, unit surface normal per vertex: every face an operation makes or
//!        changes must then turn the normals' way at each corner, with sin(angle) >=
//!        options.min_corner_sine (a merged vertex takes the mean normal); keeps a coarse mesh
//!        on a surface unfolded.
//! \param kept_vertex if given, receives the old index of each vertex of the result (vertices
//!        are renumbered compactly in their old order; of a merged pair, the one that
//!        survives).
//! \pre is_pure_quad(quads), closed and manifold.
CageSimplifyStats cancel_irregular_vertices(PolyMesh& quads,
                                            const QuadSimplifyOptions& options = {},
                                            const std::vector<Vec3>* normals = nullptr,
                                            std::vector<int>* kept_vertex = nullptr);

}  // namespace qs
